"""An episode script with ``learner = "tg"``: the relational learner runs in episodes, its
trace shows the first-order tests with their bindings, its policy saves and loads back."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from relrl.episodes import RunOptions, parse_episode, run_episode

pytestmark = pytest.mark.slow  # every test here takes a second or more

ROOT = Path(__file__).resolve().parents[2]
FRUITS = ROOT / "examples" / "domains" / "fruits.pl"

EPISODE = f"""
[episode]
domain = "{FRUITS}"
seed = 2
learner = "tg"
policy_save = "policy.pl"
[world]
perception = "symbolic"
[caregiver]
contact_hold = 1
[[phase]]
name = "no objects"
steps = 20
objects = false
[[phase]]
name = "fruits"
steps = 400
"""


def test_tg_episode_traces_tests_with_bindings_and_saves_its_policy(tmp_path: Path) -> None:
    ep = parse_episode(EPISODE, tmp_path / "tg.toml")
    summary = run_episode(ep, RunOptions(out=tmp_path / "a", plots=False))
    assert summary["learner"]["name"] == "tg"
    assert summary["memory"]["tests"] >= 1 and summary["memory"]["statistics"] > 0
    rows = [json.loads(x) for x in (tmp_path / "a" / "trace.jsonl").read_text().splitlines()]
    assert all(r["explanation"]["learner"] == "tg" for r in rows)
    # somewhere the gaze-following test held with the place bound to where the face looked
    bound = [(r, step) for r in rows for step in r["explanation"]["path"]
             if step["holds"] and step["bindings"]]
    assert bound
    places = {"left", "left_down", "down", "right_down", "right", "centre"}
    assert all(set(step["bindings"].values()) <= places for _, step in bound)
    assert any(step["test"] == "gaze(face, P), action(look(P))"
               and r["response"] == f"look({step['bindings']['P']})" for r, step in bound)
    policy = (tmp_path / "a" / "policy.pl").read_text()
    assert policy.startswith("% relrl policy: tg learner") and "tg_tree(" in policy
    # the policy loads back through the script's policy_load (read as data)
    again = parse_episode(EPISODE.replace("seed = 2", f'seed = 2\npolicy_load = '
                                          f'"{tmp_path / "a" / "policy.pl"}"'), "p.toml")
    b = run_episode(again, RunOptions(plots=False))
    assert b["memory"]["tests"] >= summary["memory"]["tests"]
