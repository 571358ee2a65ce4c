"""``relrl experiment scaling``: outputs, repeatability, time to threshold, transfer, options."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from relrl.cli import main
from relrl.experiments.scaling import ScalingConfig, growth, held_out_places, run_scaling_job
from relrl.sim import layout

TINY = ["--learners", "qlearning,etg", "--sizes", "5,9", "--seeds", "0", "--budget", "1000",
        "--block", "500", "--eval-runs", "2", "--eval-steps", "100", "--transfer-sizes", "5"]


@pytest.mark.slow
def test_outputs_and_same_seeds_same_results(tmp_path: Path, capsys) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    assert main(["experiment", "scaling", *TINY, "--workers", "1", "--out", str(a)]) == 0
    out = capsys.readouterr().out
    assert "qlearning" in out and "transfer etg" in out and "to 0.9" in out
    for name in ["results.json", "timing.json", "scaling.csv", "curves.csv", "transfer.csv",
                 "speed.csv", "memory_vs_size.png", "time_to_threshold.png", "transfer.png",
                 "domains/sis-p5-c2-k0-t2.pl", "domains/sis-p9-c2-k0-t2.pl"]:
        assert (a / name).exists(), name
    assert main(["experiment", "scaling", *TINY, "--workers", "2", "--out", str(b)]) == 0
    assert (a / "results.json").read_bytes() == (b / "results.json").read_bytes()
    results = json.loads((a / "results.json").read_text())
    assert results["partial"] is False and results["seeds"] == [0]
    cfg = results["config"]
    assert cfg["sizes"] == [5, 9] and cfg["worlds"]["9"]["places"] == 9
    assert cfg["caregiver_resolved"]["9"]["places"] == list(layout(9).toy_places)
    kinds = sorted((j["learner"], j["size"], j["kind"]) for j in results["jobs"])
    assert kinds == sorted([(lr, s, "learn") for lr in ("qlearning", "etg") for s in (5, 9)]
                           + [(lr, 5, "transfer") for lr in ("qlearning", "etg")])
    rows = list(csv.DictReader(open(a / "scaling.csv")))
    assert [(r["learner"], r["size"]) for r in rows] == [
        ("qlearning", "5"), ("qlearning", "9"), ("etg", "5"), ("etg", "9")]
    assert all(float(r["memory_positions"]) > 0 for r in rows)
    speed = list(csv.DictReader(open(a / "speed.csv")))
    assert len(speed) == 6 and all(float(r["learning_steps_per_second"]) > 0 for r in speed)


@pytest.mark.slow
def test_time_to_threshold_is_the_first_evaluation_that_reaches_it() -> None:
    cfg = ScalingConfig(learners=["qlearning"], sizes=[5], seeds=[0], budget=3000, block=500,
                        eval_runs=2, eval_steps=150, threshold=0.5, patience=0)
    job = run_scaling_job(cfg, "qlearning", 5, 0)
    curve = job["curve"]
    assert len(curve) == 3000 // 500 + 1 and job["learning_steps"] == 3000   # whole budget
    first = next((c["learning_steps"] for c in curve if c["cgi_mean"] >= 0.5), None)
    assert job["steps_to_threshold"] == first is not None
    assert curve[0]["learning_steps"] == 0 and curve[0]["memory_positions"] >= 0
    early = run_scaling_job(ScalingConfig(**{**cfg.__dict__, "patience": 1}), "qlearning", 5, 0)
    assert early["learning_steps"] == first and early["curve"] == curve[:len(early["curve"])]


@pytest.mark.parametrize("n", [2, 5, 9, 17, 33])
def test_held_out_places_are_spread_and_leave_some_to_learn(n: int) -> None:
    places = layout(n).toy_places
    out = held_out_places(places, 0.4)
    assert 1 <= len(out) < n and len(set(out)) == len(out) and set(out) <= set(places)
    assert held_out_places(layout(5).toy_places, 0.4) == ("left_down", "right_down")


@pytest.mark.slow
def test_a_transfer_job_never_sees_a_toy_at_the_held_out_places() -> None:
    cfg = ScalingConfig(learners=["etg"], sizes=[9], seeds=[1], budget=1000, block=500,
                        eval_runs=2, eval_steps=100, transfer_sizes=[9])
    job = run_scaling_job(cfg, "etg", 9, 1, "transfer")
    tr = job["transfer"]
    assert tr["unseen"] == list(held_out_places(layout(9).toy_places, 0.4))
    assert set(tr["trained"]).isdisjoint(tr["unseen"]) and 0 <= tr["cgi_unseen"] <= 1
    world = cfg.world_of(9)
    from relrl.sim import SharedAttentionEnv
    from relrl.sim.policies import GazeFollower, rollout

    placement = {p: 1.0 for p in tr["trained"]}
    env = SharedAttentionEnv(world=world, caregiver_params={"placement": placement},
                             max_steps=None)

    trace = rollout(env, GazeFollower(), 3000, seed=0)
    assert {p for rec in trace for p, _ in rec.toys}.isdisjoint(tr["unseen"])


def test_kinds_transfer_holds_out_toy_kinds(tmp_path: Path) -> None:
    cfg = ScalingConfig(learners=["qlearning"], sizes=[5], seeds=[0], budget=500, block=500,
                        eval_runs=1, eval_steps=100, transfer="kinds", transfer_sizes=[5],
                        world={"kinds": 4})
    job = run_scaling_job(cfg, "qlearning", 5, 0, "transfer")
    assert job["transfer"]["mode"] == "kinds"
    assert job["transfer"]["unseen"] == ["duck", "block"]
    assert job["transfer"]["trained"] == ["ball", "car"]


@pytest.mark.slow
def test_sizes_transfer_acts_in_larger_worlds_with_no_learning(tmp_path: Path,
                                                              capsys) -> None:
    """tg learns at P = 5 and its policy, which names no place, acts at P = 9 and 33; ETG's
    policy names its world's features and does not load there (the row says why)."""
    out = tmp_path / "sizes"
    assert main(["experiment", "scaling", "--learners", "tg,etg", "--sizes", "5", "--seeds",
                 "0", "--budget", "2000", "--block", "1000", "--eval-runs", "2",
                 "--eval-steps", "150", "--transfer", "sizes", "--transfer-from", "5",
                 "--transfer-sizes", "9,33", "--workers", "1", "--out", str(out)]) == 0
    assert "P=5 -> P=33" in capsys.readouterr().out
    results = json.loads((out / "results.json").read_text())
    transfer = [j for j in results["jobs"] if j["kind"] == "transfer"]
    assert sorted((j["learner"], j["size"]) for j in transfer) == [("etg", 5), ("tg", 5)]
    tg = results["summary"]["transfer"]["tg"]
    assert set(tg) == {"9", "33"} and all(r["from"] == 5 for r in tg.values())
    assert all(r["cgi_unseen"] is not None and "errors" not in r for r in tg.values())
    by_size = next(j for j in transfer if j["learner"] == "tg")["transfer"]["by_size"]
    assert by_size["33"]["memory_positions"] == by_size["9"]["memory_positions"] > 0
    etg = results["summary"]["transfer"]["etg"]["33"]
    assert etg["cgi_unseen"] is None and "features differ" in etg["errors"][0]
    rows = list(csv.DictReader(open(out / "transfer.csv")))
    assert [(r["learner"], r["size"]) for r in rows] == [("tg", "9"), ("tg", "33"),
                                                         ("etg", "9"), ("etg", "33")]
    assert (out / "domains" / "sis-p33-c2-k0-t2.pl").exists()


@pytest.mark.parametrize("size", [5, 33, 129])
def test_tg_candidates_do_not_depend_on_the_world_size(size: int, tmp_path: Path) -> None:
    """The generated worlds' bias names no place: an empty tree's candidate tests are the
    same at every size, and relrl check has no warning about the bias."""
    from relrl.kb import KnowledgeBase
    from relrl.sim.world import World
    from relrl.terms import Var
    from relrl.validate import bias_warnings

    with KnowledgeBase(World(places=size).write_domain(tmp_path)) as kb:
        _, _, refinements, _ = kb.call("relrl_check:bias_listing", kb.module, Var())[0]
        assert bias_warnings(kb) == []
    with KnowledgeBase(World(places=5).write_domain(tmp_path)) as kb:
        _, _, at_five, _ = kb.call("relrl_check:bias_listing", kb.module, Var())[0]
    assert refinements == at_five and len(refinements) == 19


def test_growth_is_the_log_log_slope() -> None:
    summary = {"learn": {"a": {"5": {"memory_positions": 100.0},
                               "10": {"memory_positions": 400.0}},
                         "b": {"5": {"memory_positions": 50.0},
                               "20": {"memory_positions": 200.0}}}}
    g = growth(summary)
    assert g["a"]["memory_slope"] == pytest.approx(2.0)
    assert g["b"]["memory_slope"] == pytest.approx(1.0) and g["b"]["size_ratio"] == 4


@pytest.mark.parametrize(("args", "message"), [
    (["--sizes", "1"], "places=1"),
    (["--sizes", "five"], "--sizes must be comma-separated integers"),
    (["--budget", "100", "--block", "500"], "--budget (100) must be at least --block (500)"),
    (["--threshold", "2"], "--threshold must be in (0, 1]"),
    (["--world", "plces=3"], "did you mean 'places'"),
    (["--world", "places=9"], "give the places with --sizes"),
    (["--world", "toys=7"], "toys=7"),
    (["--transfer", "kinds"], "--transfer kinds needs at least 2 toy kinds"),
    (["--holdout", "1.5"], "--holdout must be between 0 and 1"),
    (["--learners", "sarsa"], "unknown learner 'sarsa'"),
    (["--patience", "-1"], "--patience must be 0 or more"),
    (["--transfer-sizes", "x"], "--transfer-sizes must be comma-separated integers"),
    (["--transfer", "sizes", "--transfer-from", "1"], "--transfer-from 1: "),
    (["--transfer", "sizes", "--transfer-sizes", "5,300"], "--transfer-sizes 300: "),
    (["--seeds", "1,1"], "--seeds must be distinct"),
    (["--caregiver-param", "reliability=7"], "reliability=7"),
    (["--caregiver-param", "placement={\"left\": 1}"],
     "--transfer places sets the placement weights"),
    (["--eval-runs", "0"], "--eval-runs must be at least 1"),
    (["--workers", "0"], "--workers must be at least 1"),
    (["--timeout", "nan"], "--timeout: time limit"),
    (["--timeout", "0"], "--timeout: time limit"),
])
def test_bad_sweep_options_one_line_exit_2(args: list[str], message: str, tmp_path: Path,
                                           capsys) -> None:
    assert main(["experiment", "scaling", *args, "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "x").exists()
