"""Nothing learned is lost: a lost serial port or camera, a fault in a domain's rules, a bug,
a signal -- ``relrl run`` writes the summary and the policy so far, marked partial, and then
ends with one line (or the stop message) -- and interrupted evaluations are flagged."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from head.fake import FakeController, PtyController
from relrl.episodes import RunOptions, StopRequest, parse_episode, run_episode
from tests.cli.conftest import FRUITS, ROOT, episode_text, one_line_exit_2
from tests.head.conftest import FAST_TOML

LONG = episode_text(steps=100000)
#: the fast test head with a motor script for every response of the fruits domain.
HEAD = FAST_TOML + "".join(f'\n[scripts."look({d})"]\nsteps = [{{ direction = "{d}" }}]\n'
                           for d in ("centre", "left_down", "right_down", "right"))


def _lines(path: Path) -> int:
    try:
        return path.read_text().count("\n")
    except FileNotFoundError:
        return 0


def _when_traced(trace: Path, steps: int, action, timeout: float = 30) -> threading.Thread:
    """Run ``action`` in a thread once ``trace`` has ``steps`` lines."""
    def watch() -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and _lines(trace) < steps:
            time.sleep(0.01)
        action()

    thread = threading.Thread(target=watch, daemon=True)
    thread.start()
    return thread


def _assert_kept(out: Path, *, policy: str = "policy.pl") -> dict:
    """summary.json and the policy are there, the summary marked partial and consistent with
    the trace; the folder's record says partial."""
    summary = json.loads((out / "summary.json").read_text())
    steps = _lines(out / "trace.jsonl")
    assert summary["partial"] and summary["stopped_early"] and summary["steps"] >= 1
    assert summary["steps"] == steps
    text = (out / policy).read_text()
    assert "relrl_policy(" in text and "(partial)" in text
    assert summary["policy"] == policy
    record = json.loads((out / ".relrl-run.json").read_text())
    assert record["status"] == "partial" and "summary.json" in record["files"]
    return summary


@pytest.mark.parametrize("protocol", ["ssc32", "maestro", "pms5005"])
def test_a_lost_serial_port_keeps_the_summary_and_the_policy(capsys, tmp_path, protocol):
    (tmp_path / "long.toml").write_text(LONG)
    (tmp_path / "fast.toml").write_text(HEAD)
    out = tmp_path / "out"
    with PtyController(FakeController(protocol)) as pty:
        watcher = _when_traced(out / "trace.jsonl", 3, pty.hang_up)
        line = one_line_exit_2(capsys, [
            "run", str(tmp_path / "long.toml"), "--head", pty.port, "--protocol", protocol,
            "--calibration", str(tmp_path / "fast.toml"), "--out", str(out), "--no-plots"],
            pty.port, "summary.json and policy.pl written", "(partial)")
        watcher.join()
    summary = _assert_kept(out)
    assert pty.port in summary["error"] and f"time unit {summary['steps']} of 100000" in line


def test_a_deleted_camera_folder_keeps_the_summary_and_the_policy(capsys, tmp_path):
    import cv2

    from perception.render import SceneView, render

    frames = tmp_path / "frames"
    frames.mkdir()
    for k in range(40):
        view = SceneView("centre" if k % 2 else "left", "frontal", {"left": "apple"}, 1.0, k)
        cv2.imwrite(str(frames / f"{k:03d}.png"), render(view, (160, 120)))
    (tmp_path / "cam.toml").write_text(LONG)
    out = tmp_path / "out"

    def delete() -> None:
        for f in frames.iterdir():
            f.unlink()
        frames.rmdir()

    watcher = _when_traced(out / "trace.jsonl", 4, delete)
    one_line_exit_2(capsys, ["run", str(tmp_path / "cam.toml"), "--camera", str(frames),
                             "--out", str(out), "--no-plots"],
                    str(frames), "summary.json and policy.pl written")
    watcher.join()
    _assert_kept(out)


BOOM = """
looking_frontal(face) :- percept(hear(boom)), atom_length(_, _).
"""


def test_a_rule_that_raises_an_error_keeps_what_was_learned(capsys, tmp_path):
    domain = tmp_path / "boom.pl"
    domain.write_text(FRUITS.read_text().replace(
        "looking_frontal(face) :- at(centre), see(face).",
        BOOM.strip() + "\nlooking_frontal(face) :- at(centre), see(face)."))
    script = tmp_path / "boom.toml"
    script.write_text(episode_text('[[event]]\nt = 4\nsay = "boom"\n', steps=10)
                      .replace(str(FRUITS), str(domain)))
    out = tmp_path / "out"
    one_line_exit_2(capsys, ["run", str(script), "--out", str(out), "--no-plots"],
                    f"{domain}:53", "looking_frontal(face)", "time unit 4 of 10")
    summary = _assert_kept(out)
    assert summary["steps"] == 4 and "instantiated" in summary["error"]
    assert summary["stopped_by"] == "RuleError"


def test_a_bug_mid_run_still_writes_what_was_learned(tmp_path, monkeypatch):
    from relrl.episodes.world import EpisodeWorld

    real = EpisodeWorld.step

    def step(self, action):
        if self.t == 5:
            raise RuntimeError("a bug in the world")
        return real(self, action)

    monkeypatch.setattr(EpisodeWorld, "step", step)
    ep = parse_episode(episode_text(steps=20), tmp_path / "e.toml")
    with pytest.raises(RuntimeError) as info:
        run_episode(ep, RunOptions(out=tmp_path, plots=False))
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["partial"] and summary["steps"] == 5 and summary["error"] == "a bug in the world"
    assert summary["stopped_by"] == "RuntimeError"
    assert "policy.pl written" in info.value.kept


def test_a_second_ctrl_c_still_writes_what_was_learned(tmp_path):
    ep = parse_episode(episode_text(steps=20), tmp_path / "e.toml")

    class Words:
        n = 0

        def get_nowait(self):
            self.n += 1
            if self.n == 8:
                raise KeyboardInterrupt
            import queue
            raise queue.Empty

    with pytest.raises(KeyboardInterrupt):
        run_episode(ep, RunOptions(out=tmp_path, plots=False, words=Words()))
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["partial"] and summary["steps"] == 7 and (tmp_path / "policy.pl").exists()


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_stops_after_the_time_unit_with_everything_written(tmp_path, signum):
    (tmp_path / "long.toml").write_text(LONG)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "relrl", "run", str(tmp_path / "long.toml"),
                             "--out", str(out), "--no-plots"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=ROOT)
    deadline = time.monotonic() + 240  # generous: a loaded CI machine starts Python slowly
    while time.monotonic() < deadline and _lines(out / "trace.jsonl") < 20:
        time.sleep(0.05)
    assert _lines(out / "trace.jsonl") >= 20, "the run did not start in time"
    os.kill(proc.pid, signum)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signum, stderr
    summary = _assert_kept(out)
    assert summary["stopped_by"] == signal.Signals(signum).name
    assert f"by {signal.Signals(signum).name}" in stderr and "Traceback" not in stderr


EVALUATED = episode_text(steps=6).replace(
    "[[phase]]", "[evaluation]\nevery = 3\nruns = 4\nsteps = 10\n[[phase]]")


class StopAfter(StopRequest):
    """A stop request that comes after ``n`` looks (the run looks before every time unit)."""

    def __init__(self, n: int) -> None:
        super().__init__()
        self.n = n

    def __call__(self) -> bool:
        self.n -= 1
        self.requested = self.requested or self.n < 0
        return self.requested


def test_an_interrupted_evaluation_point_is_flagged(tmp_path):
    ep = parse_episode(EVALUATED, tmp_path / "e.toml")
    full = run_episode(ep, RunOptions(plots=False))
    assert [p["interrupted"] for p in full["evaluation"]] == [False, False, False]
    assert all(p["runs"] == {"done": 4, "planned": 4} for p in full["evaluation"])
    # stop in the middle of the second point's third run: 1 + 4*11 (first point) + 3 learning
    # units + 1 + 2*11 + 5 looks
    cut = run_episode(ep, RunOptions(out=tmp_path / "out", plots=False),
                      StopAfter(1 + 44 + 3 + 1 + 22 + 5))
    first, second = cut["evaluation"]
    assert not first["interrupted"] and first == full["evaluation"][0]
    assert second["interrupted"] and second["runs"] == {"done": 2, "planned": 4}
    assert second["cgi_runs"] == full["evaluation"][1]["cgi_runs"][:2]
    assert cut["partial"]
    saved = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert saved["evaluation"][1]["interrupted"]
