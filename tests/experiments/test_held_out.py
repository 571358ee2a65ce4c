"""``relrl experiment sis --train-places/--eval-places`` with tg among the learners (the
place split itself: test_sis_experiment.py); tg learns in the simulator."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from relrl.cli import main
from relrl.experiments.sis import SISConfig, run_job

SMALL = ["--points", "1", "--eval-runs", "2", "--eval-steps", "150", "--block", "300"]


@pytest.mark.slow
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


@pytest.mark.slow
def test_tg_learns_gaze_following_in_the_simulator() -> None:
    """Issue 10's first-run target on the default task (attention once per opportunity, at
    eye contact): CGI >= 0.9 after the first 500 learning units, with a small tree."""
    cfg = SISConfig(learners=["tg"], points=1, eval_runs=5, eval_steps=300, block=500)
    result = run_job(cfg, "tg", 0)
    curve = [float(np.mean(c["cgi_runs"])) for c in result["curve"]]
    # Untrained, tg chooses uniformly among the classes of looks it can tell apart (the
    # face, the place the caregiver looks at, the rest), so it follows the gaze more often
    # than a uniform choice over the six looks would; learning still adds much.
    assert curve[0] < 0.6 and curve[1] >= 0.9 and curve[1] - curve[0] >= 0.3
    memory = result["curve"][1]["memory"]
    assert memory["positions"] == memory["nodes"] + memory["entries"]
    assert memory["statistics"] == 3 * (memory["leaves"] + memory["candidates"])
    assert memory["positions"] <= 1500 // 8
    assert result["timing"]["gateway_calls_per_step"] == pytest.approx(1.0, abs=0.02)
