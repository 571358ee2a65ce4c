"""``relrl experiment sis``: outputs, repeatability, learning, bad options."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from relrl.cli import main
from relrl.experiments.results import plot
from relrl.experiments.sis import SISConfig, run_job

SMALL = ["--points", "2", "--eval-runs", "2", "--eval-steps", "100", "--block", "300"]


@pytest.mark.slow
def test_outputs_and_same_seed_same_results(tmp_path: Path, capsys) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    assert main(["experiment", "sis", *SMALL, "--out", str(a), "--workers", "1"]) == 0
    out = capsys.readouterr().out
    assert "learner" in out and "etg" in out and "qlearning" in out and "contingency" in out
    assert "tg" in out
    for name in ["results.json", "timing.json", "fig5_cgi.csv", "fig4_eye_contacts.csv",
                 "memory.csv", "fig5_cgi.png", "fig4_eye_contacts.png"]:
        assert (a / name).exists(), name
    # two worker processes, same seed: the same results.json, byte for byte
    assert main(["experiment", "sis", *SMALL, "--out", str(b), "--workers", "2"]) == 0
    assert (a / "results.json").read_bytes() == (b / "results.json").read_bytes()
    results = json.loads((a / "results.json").read_text())
    assert results["config"]["points"] == 2 and results["seeds"] == [0]
    assert results["relrl_version"]
    for name in ["contingency", "qlearning", "etg", "tg"]:
        s = results["summary"][name]
        assert len(s["curve"]) == 3
        assert s["memory"]["positions"] > 0
        # tg reads the relational view: the engine computes no state code for it
        assert s["states_met"] is None if name == "tg" else s["states_met"] > 0
    lines = (a / "fig5_cgi.csv").read_text().splitlines()
    assert lines[0] == ("learner,point,learning_steps,cgi_mean,cgi_std,cgi_literal_mean,"
                        "cgi_literal_std,n_runs")
    assert len(lines) == 1 + 4 * 3


@pytest.mark.slow
def test_another_seed_other_numbers(tmp_path: Path) -> None:
    cfg = SISConfig(learners=["etg"], points=1, eval_runs=2, eval_steps=100, block=300)
    r0, r1 = run_job(cfg, "etg", 0), run_job(cfg, "etg", 1)
    r0.pop("timing"), r1.pop("timing")
    assert r0 != r1


@pytest.mark.parametrize("learner", ["etg", "qlearning"])
@pytest.mark.slow
def test_learning_improves_gaze_following(learner: str) -> None:
    cfg = SISConfig(learners=[learner], points=2, eval_runs=3, eval_steps=300, block=1000)
    result = run_job(cfg, learner, 0)
    curve = [float(np.mean(c["cgi_runs"])) for c in result["curve"]]
    assert curve[0] < 0.5            # no knowledge yet (chance is about 0.2)
    assert curve[-1] > curve[0] + 0.3
    # one call per step, plus a few per evaluation run (seeding, saving random streams)
    assert result["timing"]["gateway_calls_per_step"] == pytest.approx(1.0, abs=0.02)


def test_without_matplotlib_a_note(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    files = plot(tmp_path, {})
    assert files == [tmp_path / "PLOTS.txt"]
    assert "pip install 'relrl[plots]'" in files[0].read_text()


@pytest.mark.parametrize("args,message", [
    (["--learners", "sarsa"], "unknown learner 'sarsa'"),
    (["--seeds", "one"], "--seeds must be comma-separated integers"),
    (["--caregiver-param", "reliability=2"], "reliability"),
    (["--caregiver", "nobody"], "unknown caregiver model 'nobody'"),
    (["--param", "etg.alpha=3"], "alpha must be in [0, 1]"),
    (["--points", "0"], "--points must be 1 to 1,000,000,000, not 0"),
])
def test_bad_options_one_line_exit_2(args: list[str], message: str, tmp_path: Path,
                                     capsys) -> None:
    assert main(["experiment", "sis", *args, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_held_out_places_are_reported_apart(tmp_path: Path, capsys) -> None:
    out = tmp_path / "held"
    assert main(["experiment", "sis", "--learners", "qlearning", *SMALL, "--train-places",
                 "left,down,right", "--out", str(out), "--workers", "2"]) == 0
    assert "held out" in capsys.readouterr().out
    results = json.loads((out / "results.json").read_text())
    curve = results["jobs"][0]["curve"]
    groups = curve[-1]["cgi_places"]
    assert set(groups) == {"trained", "held_out"}
    assert len(groups["trained"]["runs"]) == 2             # both parts' runs pooled
    pooled = [groups[g]["cgi"] for g in ("trained", "held_out")]
    assert all(v is None or 0 <= v <= 1 for v in pooled)
    assert (out / "cgi_places.csv").read_text().startswith("learner,point,cgi_trained,")
    config = results["config"]
    assert config["train_places"] == ["left", "down", "right"] and config["eval_places"] is None


@pytest.mark.parametrize(("args", "message"), [
    (["--train-places", "left,upp"], "--train-places: unknown toy place 'upp'"),
    (["--eval-places", ","], "--eval-places needs at least one place"),
])
def test_bad_place_options_one_line_exit_2(args, message, tmp_path: Path, capsys) -> None:
    assert main(["experiment", "sis", *args, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_preset_paper_2012_is_recorded_in_results(tmp_path: Path, capsys) -> None:
    out = tmp_path / "p"
    assert main(["experiment", "sis", "--preset", "paper-2012", "--learners", "contingency,etg",
                 *SMALL, "--param", "contingency.influence=0.25", "--out", str(out),
                 "--workers", "1"]) == 0
    assert "setting: preset paper-2012" in capsys.readouterr().out
    results = json.loads((out / "results.json").read_text())
    cfg = results["config"]
    assert cfg["preset"] == "paper-2012" and cfg["setting"].startswith("preset paper-2012")
    assert cfg["caregiver"] == "paper_2012"
    learning, evaluation = cfg["caregiver_resolved"], cfg["eval_caregiver_resolved"]
    assert learning["attention_per_unit"] and evaluation["attention_per_unit"]
    assert not learning["single_look"] and learning["contact_timeout"] == 10
    assert evaluation["single_look"] and evaluation["contact_timeout"] is None
    # the preset's learner parameters for the learners run only; an option overrides them
    assert cfg["learner_params"] == {"contingency": {"max_fitness": 1.0, "influence": 0.25}}
    params = {j["learner"]: j["params"] for j in results["jobs"]}
    assert params["contingency"]["max_fitness"] == 1.0
    assert params["contingency"]["influence"] == 0.25
    assert params["etg"]["alpha"] == 0.2 and params["etg"]["epsilon"] == 0.05
    # the claims need the paper's three learners: not judged here
    assert set(results["claims"]) == {"after_first_run", "later", "eye_contacts"}
    assert all(c["held"] is None for c in results["claims"].values())


def test_fixed_task_is_the_default_setting() -> None:
    cfg = SISConfig.from_preset(None)
    assert cfg.preset is None and cfg.caregiver == "paper" and not cfg.eval_caregiver_params
    d = cfg.to_dict()
    assert "eval_caregiver_resolved" not in d and d["setting"].startswith("the fixed task")
    assert not d["caregiver_resolved"]["attention_per_unit"]
    learn, evaluation, _, _ = SISConfig.from_preset("paper-2012").place_split()
    assert learn == {} and evaluation == {"contact_timeout": None, "single_look": True}


def test_claims_judged_on_a_summary() -> None:
    from relrl.experiments.sis import paper_claims

    def learner(first: float, final: float, eyes: float) -> dict:
        return {"cgi_after_first_run": first, "cgi_final": final,
                "eye_contacts": {"mean": eyes}}

    paperlike = {"contingency": learner(0.8, 0.82, 120), "etg": learner(0.78, 0.9, 110),
                 "qlearning": learner(0.81, 0.92, 100)}
    claims = paper_claims(paperlike)
    assert [c["held"] for c in claims.values()] == [True, True, True]
    paperlike["contingency"] = learner(0.47, 0.97, 115)
    claims = paper_claims(paperlike)
    assert [c["held"] for c in claims.values()] == [False, False, True]
    assert claims["later"]["values"]["cgi_final"]["contingency"] == 0.97


@pytest.mark.parametrize("preset", [None, "paper-2012"])
def test_demo_says_which_setting_and_learners_it_ran(preset: str | None, tmp_path: Path,
                                                     capsys, monkeypatch) -> None:
    import relrl.experiments.sis as experiments_sis
    from relrl.learners import DOMAINS, learners

    ran = []

    def fake_run_sis(config, out, **kwargs):   # the banner is the test, not the run
        ran.append(config)
        return {"summary": {}}, []

    monkeypatch.setattr(experiments_sis, "run_sis", fake_run_sis)
    args = ["demo", "--out", str(tmp_path / "d")] + (["--preset", preset] if preset else [])
    assert main(args) == 0
    out = capsys.readouterr().out
    assert f"{len(learners(DOMAINS))} learners ({', '.join(learners(DOMAINS))})" in out
    assert f"setting: {ran[0].setting()}" in out
    assert ran[0].preset == preset
    assert ("setting: preset paper-2012" in out) == (preset == "paper-2012")
    assert ("setting: the fixed task" in out) == (preset is None)
