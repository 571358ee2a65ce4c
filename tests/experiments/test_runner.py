"""The job runner: results in order, events, errors as one line, lost workers, engines."""

from __future__ import annotations

import pytest

from relrl.errors import ConfigError, JobCrashed
from relrl.experiments.runner import run_jobs
from tests.experiments import jobs


@pytest.mark.parametrize("workers", [1, 2])
@pytest.mark.slow
def test_results_in_order_with_their_events(workers: int) -> None:
    seen = []
    out = run_jobs(jobs.square, [(x,) for x in range(5)], workers=workers, units=3,
                   on_event=lambda i, ev: seen.append((i, ev["point"])))
    assert [r["square"] for r in out.results] == [0, 1, 4, 9, 16]
    assert out.complete and out.interrupted is None
    assert [[ev["point"] for ev in evs] for evs in out.events] == [[0, 1, 2]] * 5
    assert sorted(seen) == [(i, p) for i in range(5) for p in range(3)]
    assert len({r["pid"] for r in out.results}) == workers      # jobs ran in the workers


@pytest.mark.slow
def test_a_relrl_error_in_a_job_stops_the_run_keeping_what_finished() -> None:
    out = run_jobs(jobs.bad_value, [(1,)])
    assert out.error == "x=1: not a good value" and out.results == [None]
    mixed = run_jobs(jobs.square_or_fail, [(x,) for x in range(4)], workers=1)
    assert [r["square"] if r else None for r in mixed.results] == [0, 1, None, None]
    assert mixed.error == "x=2: not a good value" and not mixed.complete


@pytest.mark.slow
def test_a_bug_in_a_job_keeps_its_traceback() -> None:
    with pytest.raises(JobCrashed, match=r"(?s)IndexError.*Traceback.*tests/experiments/jobs"):
        run_jobs(jobs.bug, [(0,), (5,)], workers=2)


@pytest.mark.slow
def test_a_worker_that_vanishes_stops_the_run_naming_the_job() -> None:
    out = run_jobs(jobs.vanish, [(7,)])
    assert "running (7,) ended without a result (exit status 3)" in out.error


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"engine": "spark"}, "unknown engine 'spark'"), ({"workers": 0}, "at least 1"),
    ({"address": "localhost:6379"}, "--address applies to --engine ray only")])
def test_bad_runner_options(kwargs: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        run_jobs(jobs.square, [(1,)], **kwargs)


def test_a_job_learned_again_grows_the_progress_total(monkeypatch) -> None:
    """A restart (a check event that restarts) adds a job's points less its first
    evaluation to the bar: the bar ends full, not past its total."""
    from relrl.experiments import runner

    bars = []

    made = runner.ProgressBar

    def keep(total: int):
        bars.append(made(total))
        return bars[-1]

    monkeypatch.setattr(runner, "ProgressBar", keep)
    out = run_jobs(jobs.learned_again, [(1,), (2,)], workers=1, units=3)
    assert out.complete
    assert bars[0].total == 2 * 3 + 2 * 2 and bars[0].done == bars[0].total
