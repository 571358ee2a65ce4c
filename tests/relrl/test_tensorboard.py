"""TensorBoard's own reader reads relrl's event files: of a session (every time unit, each
evaluation and naming execution), of the experiments (each learner and each job), and a
record whose checksum is wrong is refused (so the checksums are tested too)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

from relrl.tensorboard import EVENT_FILE, ScalarLog, crc32c, event_file, write_event_file


def _read(folder: Path) -> dict[str, list[tuple[int, float]]]:
    """Every scalar series TensorBoard finds in ``folder``."""
    ea = EventAccumulator(str(folder), size_guidance={"scalars": 0})
    ea.Reload()
    return {tag: [(e.step, e.value) for e in ea.Scalars(tag)] for tag in ea.Tags()["scalars"]}


def test_crc32c_is_castagnoli() -> None:
    assert crc32c(b"123456789") == 0xE3069283
    assert crc32c(b"") == 0


def test_tensorboard_reads_every_step_and_value(tmp_path: Path) -> None:
    points = [(0, {"cgi": 0.5, "nan": float("nan"), "none": None, "flag": True}),
              (500, {"cgi": 0.75, "memory/positions": 12}),
              (10**12, {"cgi": -1e-3}), (7, {"only": float("inf")})]
    write_event_file(tmp_path, points)
    got = _read(tmp_path)
    assert set(got) == {"cgi", "memory/positions"}   # NaN, None, bools, inf left out
    assert got["cgi"] == [(0, 0.5), (500, 0.75), (10**12, pytest.approx(-1e-3))]
    assert got["memory/positions"] == [(500, 12.0)]


def test_a_wrong_checksum_is_refused_by_tensorboard(tmp_path: Path) -> None:
    raw = bytearray(event_file([(1, {"cgi": 0.5}), (2, {"cgi": 0.6})], wall_time=1.0))
    raw[-1] ^= 0xFF                                      # the last record's checksum
    (tmp_path / EVENT_FILE).write_bytes(bytes(raw))
    assert _read(tmp_path)["cgi"] == [(1, 0.5)]


def test_a_growing_log_is_read_while_it_grows(tmp_path: Path, monkeypatch) -> None:
    import relrl.tensorboard as tb

    monkeypatch.setattr(tb, "FLUSH_SECONDS", 0.0)        # every add reaches the file
    log = ScalarLog(tmp_path / EVENT_FILE)
    for t in range(1, 4):
        log.add(t, {"reward": float(t)})
    assert _read(tmp_path)["reward"] == [(1, 1.0), (2, 2.0), (3, 3.0)]
    monkeypatch.setattr(tb, "FLUSH_SECONDS", 3600.0)
    log.add(4, {"reward": 4.0})
    log.add(5, {"reward": 5.0})
    log.close()
    log.close()
    assert _read(tmp_path)["reward"][-2:] == [(4, 4.0), (5, 5.0)]


@pytest.mark.slow
def test_a_session_writes_its_time_units_evaluations_and_naming(tmp_path: Path) -> None:
    from relrl.episodes import RunOptions, load_episode, run_episode
    from tests.monitor.conftest import episode

    script = episode(tmp_path, steps=40, perception="symbolic",
                     extra="[evaluation]\nevery = 20\nruns = 2\nsteps = 10\n"
                           "[naming]\nexecutions = 2\n")
    out = tmp_path / "out"
    summary = run_episode(load_episode(script), RunOptions(out=out, plots=False))
    got = _read(out)
    rows = [json.loads(line) for line in (out / "trace.jsonl").read_text().splitlines()]
    assert got["reward"] == [(r["t"], r["reward"]) for r in rows]
    assert got["necessity/socialize"] == [
        (r["t"], pytest.approx(r["activation"]["socialize"])) for r in rows]
    assert got["memory/working_memory"] == [(r["t"], r["memory_size"]) for r in rows]
    assert got["gaze/eye_contacts"][-1] == (40, summary["eye_contacts"])
    assert [v for _, v in got["evaluation/cgi_mean"]] == [
        pytest.approx(p["cgi_mean"]) for p in summary["evaluation"]]
    assert [s for s, _ in got["naming/success"]] == [1, 2]


def _curve(point: int, cgi: float) -> dict:
    return {"point": point, "learning_steps": 100 * point, "cgi_mean": cgi, "cgi_std": 0.1,
            "cgi_literal_mean": cgi / 2, "memory": {"positions": 10 + point}}


def test_an_experiment_writes_a_run_per_learner_and_per_job(tmp_path: Path) -> None:
    from relrl.experiments.results import tensorboard_runs

    results = {"summary": {"etg": {"curve": [_curve(0, 0.2), _curve(1, 0.6)],
                                   "eye_contacts": {"cumulative_mean": [0.5, 1.0, 1.5]}}},
               "jobs": [{"learner": "etg", "seed": s, "curve": [_curve(0, 0.1 * s),
                                                                 _curve(1, 0.5)]}
                        for s in (0, 3)]}
    files = tensorboard_runs(tmp_path, results)
    assert sorted(f.parent.name for f in files) == ["etg", "etg-seed0", "etg-seed3"]
    pooled = _read(tmp_path / "tensorboard" / "etg")
    assert pooled["cgi/mean"] == [(0, pytest.approx(0.2)), (100, pytest.approx(0.6))]
    assert pooled["eye_contacts/cumulative"] == [(1, 0.5), (2, 1.0), (3, 1.5)]
    job = _read(tmp_path / "tensorboard" / "etg-seed3")
    assert job["cgi/mean"][0] == (0, pytest.approx(0.3)) and job["memory/positions"][1] == \
        (100, 11.0)


def test_a_scaling_run_writes_a_run_per_job(tmp_path: Path) -> None:
    from relrl.experiments.scaling_report import tensorboard_runs

    curve = [{"learning_steps": 500 * p, "cgi_mean": 0.3 * p, "cgi_literal_mean": 0.2 * p,
              "memory_positions": 7 * p} for p in range(3)]
    jobs = [{"learner": "tg", "size": 9, "seed": 1, "kind": kind, "curve": curve}
            for kind in ("learn", "transfer")]
    files = tensorboard_runs(tmp_path, {"jobs": jobs})
    assert sorted(f.parent.name for f in files) == ["tg-p9-seed1", "tg-p9-seed1-transfer"]
    assert _read(files[0].parent)["memory/positions"] == [(0, 0.0), (500, 7.0), (1000, 14.0)]
