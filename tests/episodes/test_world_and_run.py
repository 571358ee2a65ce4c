"""The scripted world, running episodes, outputs, determinism and Ctrl-C."""

from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from relrl.cli import main
from relrl.episodes import EpisodeWorld, RunOptions, StopRequest, parse_episode, run_episode

ROOT = Path(__file__).resolve().parents[2]
FRUITS = ROOT / "examples" / "domains" / "fruits.pl"


def script(body: str, perception: str = "symbolic") -> str:
    return (f'[episode]\ndomain = "{FRUITS}"\nseed = 2\n[world]\nperception = "{perception}"\n'
            + body)


PROTOCOL = script("""
[caregiver]
contact_hold = 1
[[phase]]
name = "no objects"
steps = 10
objects = false
[[phase]]
name = "fruits"
steps = 50
""")


def test_protocol_caregiver_follows_section_5_2() -> None:
    ep = parse_episode(PROTOCOL, "p.toml")
    env = EpisodeWorld(ep)
    _, info = env.reset(seed=0, options={"focus": "left"})
    assert ("see", "environment") in info["percepts"] and ("at", "left") in info["percepts"]
    # no objects in the first phase, whatever the robot does
    for _ in range(10):
        _, _, _, _, info = env.step(("look", "centre"))
        assert info["scene"]["objects"] == {}
        assert ("hear", "attention") in info["percepts"]
    # first time unit of the fruit phase: contact -> a fruit appears, the caregiver turns
    _, _, _, _, info = env.step(("look", "centre"))
    target = info["scene"]["target"]
    assert target is not None and info["scene"]["look"] == target
    pose = {"left": "left_2", "left_down": "left_1", "down": "down", "right_down": "right_1",
            "right": "right_2"}[target]
    assert ("pose", "face", pose) in info["percepts"]
    # following the gaze: attention and the fruit's name
    _, _, _, _, info = env.step(("look", target))
    kind = info["scene"]["objects"][target]
    assert ("hear", "attention") in info["percepts"]
    assert ("see", "object") in info["percepts"] and ("at", "object", target) in info["percepts"]
    assert info["words"] == [ep.word_for(kind)]
    # naming it earns attention, then the fruit goes and the caregiver looks back
    _, _, _, _, info = env.step("name_object")
    assert ("hear", "attention") in info["percepts"]
    assert info["scene"]["objects"] == {} and info["scene"]["look"] == "centre"


def test_script_events_and_typed_words() -> None:
    ep = parse_episode(script("""
[[phase]]
steps = 4
caregiver = "script"
[[event]]
t = 2
show = { right = "lime" }
look = "right"
say = ["lemon"]
attention = true
[[event]]
t = 3
remove = "all"
"""), "e.toml")
    env = EpisodeWorld(ep)
    env.reset(seed=0, options={"focus": "right"})
    _, _, _, _, info = env.step(("look", "right"))
    assert info["percepts"] == [("see", "environment"), ("at", "right")]
    env.hear("banana")
    _, _, _, _, info = env.step(("look", "right"))
    assert info["percepts"] == [("see", "object"), ("colour", "object", "green"),
                                ("at", "object", "right"), ("at", "right"),
                                ("hear", "attention"), ("hear", "lemon"), ("hear", "banana")]
    _, _, _, _, info = env.step(("look", "centre"))
    assert info["percepts"][:2] == [("see", "face"), ("pose", "face", "right_2")]
    assert info["scene"]["objects"] == {}


@pytest.mark.slow
def test_run_writes_trace_summary_policy_and_is_deterministic(tmp_path: Path) -> None:
    ep = parse_episode(PROTOCOL, tmp_path / "p.toml")
    a = run_episode(ep, RunOptions(out=tmp_path / "a", plots=False))
    run_episode(ep, RunOptions(out=tmp_path / "b", plots=False))
    assert (tmp_path / "a" / "summary.json").read_text() == \
        (tmp_path / "b" / "summary.json").read_text()
    assert (tmp_path / "a" / "trace.jsonl").read_text() == \
        (tmp_path / "b" / "trace.jsonl").read_text()
    rows = [json.loads(x) for x in (tmp_path / "a" / "trace.jsonl").read_text().splitlines()]
    assert [r["t"] for r in rows] == list(range(1, 61))
    for key in ("percepts", "memory", "necessity", "activation", "reward", "response",
                "explanation"):
        assert key in rows[0]
    assert rows[0]["explanation"]["learner"] == "etg"
    assert a["steps"] == 60 and not a["stopped_early"]
    assert a["rewards"]["total"] == sum(r["reward"] for r in rows)
    assert a["eye_contacts"] >= 1 and a["shifts"] >= 1
    assert (tmp_path / "a" / "policy.pl").read_text().count("relrl_policy") >= 1
    # the saved policy loads back through the script's policy_load
    again = parse_episode(PROTOCOL.replace("seed = 2", f'seed = 2\npolicy_load = '
                                           f'"{tmp_path / "a" / "policy.pl"}"'), "p.toml")
    c = run_episode(again, RunOptions(plots=False))
    assert c["memory"]["leaves"] >= a["memory"]["leaves"]


def test_stop_request_ends_cleanly(tmp_path: Path) -> None:
    ep = parse_episode(PROTOCOL, tmp_path / "p.toml")
    stop = StopRequest()
    seen = []

    class Count:
        def get_nowait(self):
            seen.append(1)
            if len(seen) == 7:
                stop.requested = True
            raise queue.Empty

    s = run_episode(ep, RunOptions(out=tmp_path, plots=False, words=Count()), stop)
    assert s["stopped_early"] and s["steps"] == 7
    lines = (tmp_path / "trace.jsonl").read_text().splitlines()
    assert len(lines) == 7
    assert json.loads((tmp_path / "summary.json").read_text())["steps"] == 7


@pytest.mark.slow
def test_ctrl_c_in_a_real_process(tmp_path: Path) -> None:
    path = tmp_path / "long.toml"
    path.write_text(script('[caregiver]\ncontact_hold = 1\n[[phase]]\nsteps = 100000\n'))
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "relrl", "run", str(path), "--out",
                             str(out), "--no-plots"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=ROOT)
    trace = out / "trace.jsonl"
    deadline = time.time() + 30
    while time.time() < deadline and (not trace.exists() or trace.stat().st_size < 2000):
        time.sleep(0.1)
    os.kill(proc.pid, signal.SIGINT)
    _, stderr = proc.communicate(timeout=30)
    assert proc.returncode == 130, stderr
    summary = json.loads((out / "summary.json").read_text())
    lines = trace.read_text().splitlines()
    assert summary["stopped_early"] and summary["steps"] == len(lines) > 0
    assert json.loads(lines[-1])["t"] == summary["steps"]
    assert (out / "policy.pl").exists()
    assert "stopped after time unit" in stderr


def test_live_session_prints_and_hears_typed_words(tmp_path: Path, capsys, monkeypatch) -> None:
    import io

    path = tmp_path / "live.toml"
    path.write_text(script('[[phase]]\nsteps = 3\ncaregiver = "script"\n'))
    monkeypatch.setattr(sys, "stdin", io.StringIO("apple\n"))
    assert main(["run", str(path), "--live", "--step-seconds", "0.05"]) == 0
    out = capsys.readouterr().out
    assert out.count("perceives:") == 3 and "wants:" in out and "does:" in out
    assert "hear(apple)" in out


def test_evaluation_does_not_rewind_the_learning_phases(tmp_path: Path) -> None:
    ep = parse_episode(script("""
[caregiver]
contact_hold = 1
[[phase]]
name = "no objects"
steps = 5
objects = false
[[phase]]
name = "fruits"
steps = 20
[evaluation]
every = 5
runs = 1
steps = 5
"""), tmp_path / "e.toml")
    s = run_episode(ep, RunOptions(out=tmp_path, plots=False))
    assert [p["units"] for p in s["evaluation"]] == [0, 5, 10, 15, 20, 25]
    rows = [json.loads(x) for x in (tmp_path / "trace.jsonl").read_text().splitlines()]
    assert not any(r["caregiver"]["objects"] for r in rows if r["phase"] == "no objects")
    assert any(r["caregiver"]["objects"] for r in rows if r["t"] > 10)
