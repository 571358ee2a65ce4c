"""Nothing learned is lost: a lost serial port or camera, a fault in a domain's rules, a bug,
a signal (two Ctrl-C in a row, SIGHUP to an experiment), a full disk, the output folder
deleted -- ``relrl run`` writes the summary and the policy so far, marked partial, and then
ends with one line (or the stop message) -- and interrupted evaluations are flagged. Signals
are real signals to a real process; the full disk is a real small tmpfs."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from head.fake import FakeController, PtyController
from relrl.cli import main
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


@pytest.mark.slow
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
@pytest.mark.slow
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
    # stop in the middle of the second point's third run. Looks: 1 before the first unit,
    # 4 runs x 12 (1 before the run, 1 per step of 10, 1 after it), 2 more for unit 1 and 3
    # each for units 2 and 3 (before, in and after the unit), 1 before unit 4, two runs of 12,
    # then 1 + 5 into the third run
    cut = run_episode(ep, RunOptions(out=tmp_path / "out", plots=False),
                      StopAfter(1 + 4 * 12 + 2 + 2 * 3 + 1 + 2 * 12 + 1 + 5))
    first, second = cut["evaluation"]
    assert not first["interrupted"] and first == full["evaluation"][0]
    assert second["interrupted"] and second["runs"] == {"done": 2, "planned": 4}
    assert second["cgi_runs"] == full["evaluation"][1]["cgi_runs"][:2]
    assert cut["partial"]
    saved = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert saved["evaluation"][1]["interrupted"]


# ---- real signals, a full disk, a folder deleted: what a session keeps ----------------------

def _start(*argv: str, stderr: Any = subprocess.PIPE) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "relrl", *argv], cwd=ROOT, text=True,
                            stdout=subprocess.PIPE, stderr=stderr, stdin=subprocess.DEVNULL)


def _wait_traced(out: Path, steps: int, proc: subprocess.Popen) -> None:
    deadline = time.monotonic() + 240  # generous: a loaded machine starts Python slowly
    while time.monotonic() < deadline and proc.poll() is None and \
            _lines(out / "trace.jsonl") < steps:
        time.sleep(0.02)
    assert _lines(out / "trace.jsonl") >= steps, f"the run did not start (exit {proc.poll()})"


def _no_leftovers(out: Path) -> None:
    """No temporary file, nor relrl's journal or held-back space, is left in ``out``."""
    left = [p.name for p in out.rglob("*") if p.name.endswith(".tmp")
            or p.name in (".relrl-run.files", ".relrl-run.spare")]
    assert left == [], left


@pytest.mark.parametrize("gap", [0.0, 0.05])
@pytest.mark.slow
def test_two_ctrl_c_in_a_row_keep_the_summary_timing_and_policy(tmp_path, gap):
    """Real SIGINTs to a real ``relrl run``: the second comes while the first one's outputs
    are being written, and waits for them."""
    (tmp_path / "long.toml").write_text(LONG)
    out = tmp_path / "out"
    proc = _start("run", str(tmp_path / "long.toml"), "--out", str(out), "--no-plots")
    _wait_traced(out, 20, proc)
    os.kill(proc.pid, signal.SIGINT)
    time.sleep(gap)
    os.kill(proc.pid, signal.SIGINT)
    _, stderr = proc.communicate(timeout=120)
    # 130 (exit 128 + 2), or -2: the second came as Python was ending, everything written
    # (a shell shows both as 130)
    assert proc.returncode in (130, -signal.SIGINT), stderr
    assert "Traceback" not in stderr and len(stderr.strip().splitlines()) == 1, stderr
    summary = _assert_kept(out)
    assert json.loads((out / "timing.json").read_text())["learning_steps"] == summary["steps"]
    _no_leftovers(out)


def _read_all(fd: int, into: list[bytes]) -> None:
    while True:
        try:
            chunk = os.read(fd, 4096)
        except OSError:  # the other side closed
            return
        if not chunk:
            return
        into.append(chunk)


@pytest.mark.slow
def test_sighup_stops_an_experiment_keeping_every_finished_point(tmp_path):
    """The terminal closed (a real SIGHUP): the experiment stops like on Ctrl-C, writing
    the points that finished, marked partial; exit 128 + 1."""
    import pty

    out = tmp_path / "out"
    master, slave = pty.openpty()  # a terminal: the progress bar shows each point
    proc = _start("experiment", "sis", "--learners", "etg", "--points", "2000",
                  "--eval-runs", "1", "--eval-steps", "20", "--block", "20", "--workers", "1",
                  "--out", str(out), stderr=slave)
    os.close(slave)
    shown: list[bytes] = []
    reader = threading.Thread(target=_read_all, args=(master, shown), daemon=True)
    reader.start()
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline and proc.poll() is None \
            and b"point 3" not in b"".join(shown):
        time.sleep(0.05)
    assert proc.poll() is None, b"".join(shown).decode(errors="replace")
    os.kill(proc.pid, signal.SIGHUP)
    stdout, _ = proc.communicate(timeout=120)
    reader.join(timeout=10)
    os.close(master)
    assert proc.returncode == 128 + signal.SIGHUP, b"".join(shown)[-2000:]
    assert "stopped by SIGHUP" in stdout
    results = json.loads((out / "results.json").read_text())
    assert results["partial"] and results["interrupted_by"] == "SIGHUP"
    assert len(results["summary"]["etg"]["curve"]) >= 3
    record = json.loads((out / ".relrl-run.json").read_text())
    assert record["status"] == "partial" and "results.json" in record["files"]
    _no_leftovers(out)


def _on_a_small_disk(tmp_path: Path, argv: list[str], size: str = "200k"
                     ) -> tuple[subprocess.CompletedProcess, Path]:
    """Run ``relrl ARGV`` with ``{disk}`` a fresh tmpfs of ``size`` (its own mount namespace:
    nothing is left mounted); returns the process and a copy of what the disk held."""
    disk, copy = tmp_path / "disk", tmp_path / "copy"
    disk.mkdir()
    copy.mkdir()
    unshare = ["unshare", "--mount"] if os.geteuid() == 0 else \
        ["unshare", "--user", "--map-root-user", "--mount"]
    shell = ('mount -t tmpfs -o size="$SIZE" relrl-test "$DISK" || exit 97; "$@"; rc=$?; '
             'cp -a "$DISK/." "$COPY/"; exit $rc')
    proc = subprocess.run([*unshare, "sh", "-c", shell, "sh", sys.executable, "-m", "relrl",
                           *[a.format(disk=disk) for a in argv]],
                          env={**os.environ, "DISK": str(disk), "COPY": str(copy),
                               "SIZE": size},
                          cwd=ROOT, capture_output=True, text=True, timeout=600)
    if proc.returncode == 97 or "unshare:" in proc.stderr:
        pytest.fail(f"a small tmpfs could not be mounted here: {proc.stderr.strip()}")
    return proc, copy


@pytest.mark.parametrize("flags", [[], ["--record", "--camera", "synthetic://?size=160x120",
                                        "--record-rate", "0"]], ids=["trace", "frames"])
@pytest.mark.slow
def test_a_full_disk_ends_in_one_line_with_what_fits_written(tmp_path, flags):
    """A real 200 KB tmpfs fills up: one line, exit 2, the summary and the policy written in
    the space held back, the record says partial, no temporary file anywhere."""
    (tmp_path / "long.toml").write_text(LONG)
    proc, copy = _on_a_small_disk(tmp_path, ["run", str(tmp_path / "long.toml"), "--out",
                                             "{disk}/out", "--no-plots", *flags])
    out = copy / "out"
    lines = [x for x in proc.stderr.splitlines() if x.strip()]
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "No space left on device" in lines[0] and "(partial)" in lines[0], lines[0]
    assert "Traceback" not in proc.stderr
    summary = _assert_kept(out)
    assert "No space left on device" in summary["error"]
    for line in (out / "trace.jsonl").read_text().splitlines():  # whole lines only
        json.loads(line)
    _no_leftovers(out)


@pytest.mark.slow
def test_an_experiment_on_a_full_disk_keeps_its_results(tmp_path):
    """The figures do not fit: results.json does (one line, exit 2, the record partial)."""
    proc, copy = _on_a_small_disk(tmp_path, [
        "experiment", "sis", "--learners", "etg", "--points", "2", "--eval-runs", "1",
        "--eval-steps", "20", "--block", "20", "--workers", "1", "--out", "{disk}/out"],
        size="120k")
    out = copy / "out"
    lines = [x for x in proc.stderr.splitlines() if x.strip()]
    assert proc.returncode == 2 and "No space left on device" in lines[-1], proc.stderr
    assert "Traceback" not in proc.stderr
    assert json.loads((out / "results.json").read_text())["summary"]["etg"]["curve"]
    record = json.loads((out / ".relrl-run.json").read_text())
    assert record["status"] == "partial" and "results.json" in record["files"]
    _no_leftovers(out)


def test_deleting_out_mid_run_ends_in_one_line_not_a_success(capsys, tmp_path):
    """The folder removed under a running session: exit 2 saying so, not "wrote
    trace.jsonl" -- and the folder is not made again behind the user's back."""
    import shutil

    (tmp_path / "long.toml").write_text(LONG)
    out, gone = tmp_path / "out", tmp_path / "gone"

    def delete() -> None:  # `rm -rf out`, done at once: the session may write as it goes
        out.rename(gone)
        while gone.exists():
            shutil.rmtree(gone, ignore_errors=True)

    watcher = _when_traced(out / "trace.jsonl", 5, delete)
    code = main(["run", str(tmp_path / "long.toml"), "--out", str(out), "--no-plots"])
    watcher.join()
    captured = capsys.readouterr()
    lines = [x for x in captured.err.splitlines() if x.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in captured.err, captured.err
    assert "deleted" in lines[0] and str(out) in lines[0], lines[0]
    assert "wrote" not in captured.out
    assert not out.exists()


def test_a_recording_stopped_by_the_same_full_disk_adds_no_second_line(capsys, tmp_path,
                                                                      monkeypatch):
    """The order a busy machine gives: the session's own write fails first, and the
    recording's writer, stopped by the same full disk, fails only when it is closed. The
    user reads one line (the first error, with what was kept), not a warning before it."""
    from relrl.episodes.recording import SessionTap
    from relrl.errors import OutputError

    (tmp_path / "long.toml").write_text(LONG)
    step, close = SessionTap.step, SessionTap.close

    def full_step(self, record, phase, **kw):
        if self.run.t >= 5:
            raise OutputError(f"cannot write {self.out / 'trace.jsonl'}: "
                              "No space left on device")
        return step(self, record, phase, **kw)

    def failed_close(self, *args, **kw):
        close(self, *args, **kw)
        raise OutputError("the recording's writer stopped: No space left on device")

    monkeypatch.setattr(SessionTap, "step", full_step)
    monkeypatch.setattr(SessionTap, "close", failed_close)
    line = one_line_exit_2(capsys, ["run", str(tmp_path / "long.toml"), "--out",
                                    str(tmp_path / "out"), "--no-plots"],
                           "No space left on device", "(partial)")
    assert "writer stopped" not in line, line
    assert "recording's writer stopped" in (tmp_path / "out" / "run.log").read_text()
