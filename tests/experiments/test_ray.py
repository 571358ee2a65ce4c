"""Sweeps on Ray: a local Ray instance (2 CPUs) runs the same jobs as the local workers and
writes the same results.json, byte for byte."""

from __future__ import annotations

from pathlib import Path

import pytest
import ray  # the extra relrl[ray]: make test installs it

from relrl.cli import main
from relrl.experiments.runner import run_jobs
from tests.experiments import jobs

pytestmark = pytest.mark.slow  # every test here takes a second or more


@pytest.fixture(scope="module")
def local_ray():
    """One small local Ray instance for the module (run_jobs joins it, leaves it running)."""
    import os

    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    ray.init(num_cpus=2, include_dashboard=False, logging_level="ERROR", log_to_driver=False)
    yield
    ray.shutdown()


SCALING = ["scaling", "--learners", "qlearning,etg", "--sizes", "5,9", "--seeds", "0",
           "--budget", "600", "--block", "300", "--eval-runs", "2", "--eval-steps", "100",
           "--transfer-sizes", "5"]
SIS = ["sis", "--learners", "etg", "--points", "1", "--eval-runs", "2", "--eval-steps", "100",
       "--block", "200"]
WORLDS = ["worlds", "--worlds", str(Path(__file__).resolve().parents[2] / "examples" / "worlds"
                                    / "blocks.pl"),
          "--tasks", "stack", "--learners", "tg,qtable", "--seeds", "0", "--episodes", "20",
          "--block", "10", "--eval-episodes", "5", "--sizes", "3", "--test-sizes", "4"]


@pytest.mark.parametrize("args", [SCALING, SIS, WORLDS], ids=["scaling", "sis", "worlds"])
def test_ray_results_are_byte_identical_to_the_local_run(args: list[str], local_ray,
                                                         tmp_path: Path) -> None:
    a, b = tmp_path / "local", tmp_path / "ray"
    assert main(["experiment", *args, "--workers", "2", "--out", str(a)]) == 0
    assert main(["experiment", *args, "--engine", "ray", "--out", str(b)]) == 0
    assert (a / "results.json").read_bytes() == (b / "results.json").read_bytes()
    assert '"engine": "ray"' in (b / "timing.json").read_text()


def test_ray_jobs_report_events_and_errors_like_local_ones(local_ray) -> None:
    out = run_jobs(jobs.square, [(x,) for x in range(3)], engine="ray", units=3)
    assert [r["square"] for r in out.results] == [0, 1, 4]
    assert [len(e) for e in out.events] == [3, 3, 3]
    assert run_jobs(jobs.bad_value, [(2,)], engine="ray").error == "x=2: not a good value"
    assert "ended without a result" in run_jobs(jobs.vanish, [(1,)], engine="ray").error


@pytest.mark.parametrize(("args", "message"), [
    (["--engine", "ray", "--address", "127.0.0.1:9"], "no Ray cluster answers there"),
    (["--engine", "ray", "--address", "nowhere"], "use HOST:PORT, ray://HOST:PORT or auto"),
    (["--address", "127.0.0.1:9"], "--address applies to --engine ray only"),
    (["--engine", "spark"], "invalid choice: 'spark'"),
])
def test_bad_engine_options_one_line_exit_2(args: list[str], message: str, tmp_path: Path,
                                            capsys) -> None:
    try:
        code = main(["experiment", *SIS, *args, "--out", str(tmp_path)])
    except SystemExit as exc:          # argparse's own errors
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
