"""Experiment 2's protocol: evaluation that never changes learning, the two time units, the
caregiver's cycles and first-shift check, naming outcomes and confusions, the sweep."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from relrl.episodes import EpisodeError, EpisodeWorld, RunOptions, parse_episode, run_episode
from relrl.episodes.script import TIME_UNITS
from relrl.experiments.exp2.measures import Naming, merge_confusions, rates, report_lines, table1
from relrl.learners import DOMAINS, learners

ROOT = Path(__file__).resolve().parents[2]
FRUITS = ROOT / "examples" / "domains" / "fruits.pl"


def script(body: str, *, perception: str = "symbolic", time_unit: str = "step",
           learner: str = "etg", extra_world: str = "") -> str:
    return (f'[episode]\ndomain = "{FRUITS}"\nseed = 4\nlearner = "{learner}"\n'
            f'time_unit = "{time_unit}"\n[world]\nperception = "{perception}"\n{extra_world}'
            '[caregiver]\ncontact_hold = 1\n' + body)


PHASES = """
[[phase]]
name = "no objects"
steps = 4
objects = false
[[phase]]
name = "fruits"
steps = 16
"""


def _learning(tmp_path: Path, text: str, name: str) -> tuple[list[dict], bytes, dict]:
    out = tmp_path / name
    ep = parse_episode(text, tmp_path / "same-name.toml")
    s = run_episode(ep, RunOptions(out=out, plots=False))
    rows = [json.loads(x) for x in (out / "trace.jsonl").read_text().splitlines()]
    return rows, (out / "policy.pl").read_bytes(), s


@pytest.mark.parametrize("time_unit", TIME_UNITS)
@pytest.mark.parametrize("learner", learners(DOMAINS))
@pytest.mark.slow
def test_learning_is_identical_whatever_the_evaluation_interval(tmp_path, learner,
                                                                time_unit) -> None:
    base = script(PHASES, learner=learner, time_unit=time_unit)
    runs = {"none": base,
            "every3": base + "[evaluation]\nevery = 3\nruns = 2\nsteps = 6\n",
            "every7": base + "[evaluation]\nevery = 7\nruns = 1\nsteps = 9\n"}
    got = {k: _learning(tmp_path, text, k) for k, text in runs.items()}
    rows, policy, summary = got["none"]
    assert len(rows) >= 20 and summary["units"] == 20
    for k in ("every3", "every7"):
        assert got[k][0] == rows, k          # every learning step, explanation included
        assert got[k][1] == policy, k        # the learned knowledge
        assert got[k][2]["cgi"] == summary["cgi"]
    assert [p["units"] for p in got["every3"][2]["evaluation"]] == [0, 3, 6, 9, 12, 15, 18]


@pytest.mark.slow
def test_learning_is_identical_on_rendered_frames(tmp_path) -> None:
    body = ('[[phase]]\nname = "no objects"\nsteps = 3\nobjects = false\n'
            '[[phase]]\nname = "fruits"\nsteps = 5\n')
    base = script(body, perception="render", time_unit="interaction",
                  extra_world='variation = "camera"\n')
    a = _learning(tmp_path, base, "plain")
    b = _learning(tmp_path, base + "[evaluation]\nevery = 4\nruns = 1\nsteps = 2\n", "eval")
    assert a[0] == b[0] and a[1] == b[1]
    assert len(b[2]["evaluation"]) == 3


def test_time_unit_is_checked(tmp_path) -> None:
    assert parse_episode(script(PHASES), "a.toml").time_unit == "step"
    with pytest.raises(EpisodeError, match=r"a.toml:5: unknown time unit 'trial'"):
        parse_episode(script(PHASES, time_unit="trial"), "a.toml")
    with pytest.raises(EpisodeError, match="counts the protocol caregiver"):
        parse_episode(script('[[phase]]\nsteps = 3\ncaregiver = "script"\n',
                             time_unit="interaction"), "a.toml")
    with pytest.raises(EpisodeError, match="cannot be used with time_unit"):
        parse_episode(script('[[phase]]\nsteps = 3\n[[event]]\nt = 2\nsay = "apple"\n',
                             time_unit="interaction"), "a.toml")
    with pytest.raises(EpisodeError, match="evaluation policy"):
        parse_episode(script(PHASES + "[evaluation]\npolicy = \"best\"\n"), "a.toml")
    with pytest.raises(EpisodeError, match="appearance variation"):
        parse_episode(script(PHASES, extra_world='variation = "fancy"\n'), "a.toml")


def _cycle(env: EpisodeWorld, follow: bool = True) -> int:
    """Play one interaction cycle as a robot that follows the gaze; returns its steps."""
    start, n = env.units_done, 0
    while env.units_done == start:
        scene = env.caregiver.scene
        action = ("look", "centre")
        if scene.mode in ("attend", "joint") and follow:
            action = "name_object" if env.focus == scene.target else ("look", scene.target)
        env.step(action)
        n += 1
        assert n < 40
    return n


def test_interaction_cycles_count_the_time_units() -> None:
    ep = parse_episode(script(PHASES, time_unit="interaction"), "c.toml")
    env = EpisodeWorld(ep)
    env.reset(seed=0, options={"focus": "centre"})
    # without objects: eye contact held `joint` (2) more units, then the next cycle
    for unit in range(1, 5):
        assert _cycle(env) == 3 and env.units_done == unit
        assert env.caregiver.scene.objects == {}
    # with objects: contact (the fruit appears), the turn, naming
    _, _, _, _, info = env.step(("look", "centre"))
    assert info["scene"]["objects"] and info["unit"] == 5 and info["phase"] == "fruits"
    assert env.units_done == 4
    assert _cycle(env) == 2 and env.units_done == 5


def test_looking_away_ends_a_cycle_without_objects() -> None:
    ep = parse_episode(script(PHASES, time_unit="interaction"), "c.toml")
    env = EpisodeWorld(ep)
    env.reset(seed=0, options={"focus": "centre"})
    env.step(("look", "centre"))
    assert env.caregiver.scene.contact and env.units_done == 0
    env.step(("look", "left"))
    assert env.units_done == 1


def test_first_shift_is_the_only_one_checked() -> None:
    ep = parse_episode(script(PHASES), "c.toml")
    env = EpisodeWorld(ep, protocol_only=True, sequence=True, first_shift=True)
    env.reset(seed=0, options={"focus": "centre"})
    _, _, _, _, info = env.step(("look", "centre"))
    target = info["scene"]["target"]
    wrong = next(p for p in ep.places if p != target)
    _, r1, _, _, info = env.step(("look", wrong))
    assert info["scene"]["objects"]                 # still there this unit ...
    _, r2, _, _, info = env.step(("look", target))  # ... but finding it now is too late
    assert info["scene"]["objects"] == {} and r1 == r2 == 0.0
    assert env.caregiver.scene.opportunity == 1


def test_appearance_is_one_room_per_run_and_one_look_per_presentation() -> None:
    ep = parse_episode(script(PHASES, perception="render", time_unit="interaction",
                              extra_world='variation = "camera"\n'), "c.toml")
    a, b = EpisodeWorld(ep), EpisodeWorld(ep, protocol_only=True)
    assert a.room == b.room
    b.reset(seed=1, options={"focus": "centre"})
    _, _, _, _, info = b.step(("look", "centre"))
    target = info["scene"]["target"]
    b.step(("look", target))
    look = b._looks[target]
    b.step(("look", target))
    assert b._looks[target] is look
    _cycle(b)
    b.step(("look", "centre"))
    assert b._looks.get(b.caregiver.scene.target) is not look


def test_naming_counts_confusions_and_misses() -> None:
    naming = Naming({"apple", "lemon"}, confident_after=1)
    red = np.array([0.9] + [0.0] * 11 + [0.1])
    assert naming.hear(["apple"], red) == "unknown"
    assert naming.hear(["apple"], red) == "success"
    assert naming.hear(["lemon"], red) == "error"       # a lemon that looks like an apple
    assert naming.hear(["lemon"], None) is None and naming.missed == 1
    assert naming.hear(["hello"], red) is None
    assert naming.confusion() == {"apple": {"apple": 1, "nothing": 1}, "lemon": {"apple": 1}}
    assert merge_confusions([naming.confusion(), {"lemon": {"lemon": 2}}]) == \
        {"apple": {"apple": 1, "nothing": 1}, "lemon": {"apple": 1, "lemon": 2}}


def _execution(presentations: int, **counts: int) -> dict:
    full = {k: counts.get(k, 0) for k in ("unknown", "correct_guess", "incorrect_guess",
                                          "error", "success")}
    return {"presentations": presentations, "counts": full, "missed": 0, "steps": 10,
            "categories": 1, "confusion": {}}


def test_no_presentation_is_said_not_reported_as_zero() -> None:
    assert rates([_execution(0), _execution(0)]) is None
    t = table1([_execution(0), _execution(0)])
    assert t["rates"] is None and "no naming presentation" in t["note"]
    text = "\n".join(report_lines({"table1": t}))
    assert "no naming presentation happened" in text and "0.00" not in text
    t = table1([_execution(0), _execution(4, unknown=1, success=3)])
    assert t["rates"]["success"] == [75.0, 0.0] and "1 of 2 executions" in t["note"]


def test_symbolic_run_without_features_says_so(tmp_path) -> None:
    body = PHASES + "[naming]\nexecutions = 2\npresentations = 3\nmax_steps = 40\n"
    s = run_episode(parse_episode(script(body), tmp_path / "n.toml"), RunOptions(plots=False))
    assert s["table1"]["rates"] is None
    assert s["table1"]["executions_without_presentation"] == 2
    assert all(e["missed"] > 0 for e in s["table1"]["executions"])


@pytest.mark.slow
def test_sweep_writes_tables_and_plots(tmp_path) -> None:
    from relrl.experiments.exp2.sweep import main

    path = tmp_path / "small.toml"
    path.write_text(script(PHASES + "[evaluation]\nevery = 10\nruns = 2\nsteps = 5\n"))
    out = tmp_path / "out"
    assert main(["--script", str(path), "--learners", "etg,qlearning", "--seeds", "0-1",
                 "--every", "10", "--workers", "1", "--out", str(out)]) == 0
    rows = list(csv.DictReader((out / "fig6.csv").open()))
    assert {(r["learner"], r["time_unit"], r["seed"]) for r in rows} == \
        {(a, u, s) for a in ("etg", "qlearning") for u in TIME_UNITS for s in ("0", "1")}
    assert sorted({int(r["units"]) for r in rows}) == [0, 10, 20]
    summary = list(csv.DictReader((out / "fig6_summary.csv").open()))
    assert len(summary) == 2 * 2 * 3
    results = json.loads((out / "results.json").read_text())
    assert results["seeds"] == [0, 1] and "etg/interaction" in results["summary"]
    for f in ("table1.csv", "table1_summary.csv", "confusion.csv", "fig6.png"):
        assert (out / f).exists(), f
    assert main(["--script", str(path), "--learners", "nope", "--out", str(out)]) == 2


def test_interaction_units_need_the_simulated_caregiver(tmp_path) -> None:
    from relrl.errors import ConfigError

    ep = parse_episode(script(PHASES, time_unit="interaction"), tmp_path / "c.toml")
    with pytest.raises(ConfigError, match="on a camera use time_unit"):
        run_episode(ep, RunOptions(camera="synthetic://?looking_at=centre", plots=False))
