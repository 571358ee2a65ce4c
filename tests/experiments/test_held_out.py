"""``relrl experiment sis --train-places/--eval-places``: places held out while learning,
the CGI on trained and held-out places apart; tg learns in the simulator."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from relrl.cli import main
from relrl.experiments.sis import SISConfig, _caregivers, _PlaceShifts, run_job
from relrl.sim.metrics import StepRecord

SMALL = ["--points", "1", "--eval-runs", "2", "--eval-steps", "150", "--block", "300"]


def record(t: int, focus: str, gaze: str) -> StepRecord:
    return StepRecord(t, focus, gaze, "attend", 0, 0, (), None, False, False)


def test_shifts_counted_by_the_place_the_caregiver_looked_at() -> None:
    shifts = _PlaceShifts({"trained": {"left", "down"}, "held_out": {"right"}})
    trace = [record(0, "centre", "left"), record(1, "left", "left"),      # followed: left
             record(2, "centre", "right"), record(3, "down", "right"),    # wrong: right
             record(4, "centre", "right"), record(5, "centre", "right"),  # no shift yet
             record(6, "right", "frontal"),                               # followed: right
             record(7, "centre", "frontal"), record(8, "left", "frontal")]  # not a shift
    for r in trace:
        shifts.add(r)
    assert shifts.counts == {"trained": [1, 1], "held_out": [1, 2]}


def test_learning_caregiver_places_toys_only_at_the_trained_places() -> None:
    config = SISConfig(train_places=["left", "left_down", "down"])
    learning, evaluation, groups = _caregivers(config)
    assert {p for p, w in learning.params.placement.items() if w > 0} == \
        {"left", "left_down", "down"}
    assert set(evaluation.params.target_sequence) == \
        {"left", "left_down", "down", "right_down", "right"}
    assert groups == {"trained": {"left", "left_down", "down"},
                      "held_out": {"right_down", "right"}}


def test_held_out_places_reported_apart(tmp_path: Path, capsys) -> None:
    out = tmp_path / "held"
    assert main(["experiment", "sis", *SMALL, "--learners", "tg,qlearning", "--out", str(out),
                 "--train-places", "left,left_down,down", "--workers", "1"]) == 0
    table = capsys.readouterr().out
    assert "trained" in table and "held out" in table
    results = json.loads((out / "results.json").read_text())
    assert results["config"]["train_places"] == ["left", "left_down", "down"]
    for name in ("tg", "qlearning"):
        groups = results["summary"][name]["cgi_places"]
        assert set(groups) == {"trained", "held_out"}
        assert len(groups["trained"]) == len(groups["held_out"]) == 2
    with open(out / "cgi_places.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["learner", "point", "cgi_trained", "cgi_held_out"]
    assert len(rows) == 1 + 2 * 2
    assert (out / "cgi_places.png").stat().st_size > 1000


@pytest.mark.parametrize("args,message", [
    (["--train-places", "left,lft"], "--train-places: unknown toy place 'lft'"),
    (["--eval-places", "centre"], "--eval-places: unknown toy place 'centre'"),
    (["--train-places", ","], "--train-places needs at least one place"),
])
def test_bad_places_one_line_exit_2(args: list[str], message: str, tmp_path: Path,
                                    capsys) -> None:
    assert main(["experiment", "sis", *args, "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]


def test_tg_learns_gaze_following_in_the_simulator() -> None:
    cfg = SISConfig(learners=["tg"], points=1, eval_runs=3, eval_steps=300, block=500)
    result = run_job(cfg, "tg", 0)
    curve = [c["cgi_mean"] for c in result["curve"]]
    assert curve[0] < 0.5 and curve[1] >= 0.9
    memory = result["curve"][1]["memory"]
    assert memory["positions"] == memory["nodes"] + memory["entries"]
    assert memory["statistics"] == 3 * (memory["leaves"] + memory["candidates"])
    assert result["timing"]["gateway_calls_per_step"] == pytest.approx(1.0, abs=0.02)
