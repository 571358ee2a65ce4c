"""A world's rules misbehaving, and ``relrl learn`` / ``relrl check --world`` /
``relrl experiment worlds`` stopped: one line, the right status, nothing learned lost."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT, default_signals

BLOCKS = ROOT / "examples" / "worlds" / "blocks.pl"
PRECONDITION = "precondition(move(X, Y), State) :-\n"


def world_with(tmp_path: Path, clause: str, name: str = "w.pl") -> tuple[Path, int]:
    """blocks.pl with ``clause`` put before its precondition/2; the path and the clause's
    line."""
    text = BLOCKS.read_text()
    assert PRECONDITION in text
    line = text[:text.index(PRECONDITION)].count("\n") + 1
    path = tmp_path / name
    path.write_text(text.replace(PRECONDITION, clause + "\n" + PRECONDITION, 1))
    return path, line


def relrl(*argv: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """``relrl ARGV`` in a process of its own (a halt or a hang cannot end the test run)."""
    return subprocess.run([sys.executable, "-m", "relrl", *argv], cwd=ROOT, text=True,
                          capture_output=True, timeout=timeout, stdin=subprocess.DEVNULL,
                          preexec_fn=default_signals)


def one_line(proc: subprocess.CompletedProcess) -> str:
    """The one line on stderr of a command that ended with status 2."""
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and "Traceback" not in proc.stderr, \
        (proc.returncode, proc.stderr[-3000:])
    return lines[0]


# ---- A: halt in a world rule --------------------------------------------------------------

@pytest.mark.parametrize("goal", ["halt", "halt(3)"])
def test_halt_in_a_world_rule_is_one_line_naming_the_rule(tmp_path: Path, goal: str) -> None:
    world, line = world_with(tmp_path, f"precondition(move(_, _), _) :- {goal}.")
    check = one_line(relrl("check", "--world", str(world)))
    assert f"w.pl:{line}: rule precondition(" in check and "called halt/0,1" in check
    out = tmp_path / "out"
    learn = one_line(relrl("learn", str(world), "--episodes", "4", "--eval-episodes", "2",
                           "--no-speed", "--out", str(out)))
    assert f"w.pl:{line}: rule precondition(" in learn and "called halt/0,1" in learn
    assert not (out / ".relrl-run.json").exists()       # refused before the folder is claimed


# ---- C: a world rule that loops or sleeps -------------------------------------------------

def started(*argv: str) -> subprocess.Popen:
    """``relrl ARGV`` started with Ctrl-C and SIGTERM at their defaults, as from a shell."""
    return subprocess.Popen([sys.executable, "-m", "relrl", *argv], cwd=ROOT, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL, preexec_fn=default_signals)


def wait_for(stream, marker: str, proc: subprocess.Popen, timeout: float = 240) -> str:
    """Read ``stream`` line by line until a line holds ``marker``; what was read."""
    import time

    seen, deadline = [], time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = stream.readline()
        if not line:
            break
        seen.append(line)
        if marker in line:
            return "".join(seen)
    proc.kill()
    raise AssertionError(f"no {marker!r} (exit {proc.poll()}): {''.join(seen)[-2000:]}")


@pytest.mark.parametrize("body", ["repeat, fail", "sleep(1000)"])
def test_a_world_rule_that_never_ends_is_stopped_at_the_rule_limit(tmp_path: Path,
                                                                     body: str) -> None:
    """The limit is a rule's, in seconds (--rule-seconds), not the batch's 600 s; the
    message names the rule and the limit."""
    import time

    world, line = world_with(tmp_path, f"precondition(move(_, _), _) :- {body}.")
    t0 = time.monotonic()
    check = one_line(relrl("check", "--world", str(world), "--rule-seconds", "1"))
    assert time.monotonic() - t0 < 60
    assert f"w.pl:{line}: rule precondition(" in check and "longer than 1 s" in check
    learn = one_line(relrl("learn", str(world), "--episodes", "4", "--no-speed",
                           "--rule-seconds", "0.5"))
    assert f"w.pl:{line}: rule precondition(" in learn and "longer than 0.5 s" in learn


def test_a_long_batch_of_a_world_is_not_a_rule_that_never_ends(tmp_path: Path) -> None:
    """Every step is a rule's end: a batch of episodes that runs many times the limit, each
    step slow but ending, is not stopped."""
    world, _ = world_with(tmp_path, "precondition(move(_, _), _) :- sleep(0.02), fail.")
    proc = relrl("learn", str(world), "--size", "3", "--eval-sizes", "3", "--episodes", "30",
                 "--block", "30", "--eval-episodes", "2", "--no-speed",
                 "--rule-seconds", "0.5")
    assert proc.returncode == 0, proc.stderr[-2000:]


def test_ctrl_c_stops_a_world_rule_that_never_ends_at_once(tmp_path: Path) -> None:
    """Ctrl-C reaches a rule that loops in `check --world` (the world's directive says when
    it has loaded): exit 130 within a second or so, not at the rule limit."""
    import signal
    import time

    world, _ = world_with(tmp_path, ":- format(user_error, \"loaded~n\", []).\n"
                                    "precondition(move(_, _), _) :- repeat, fail.")
    proc = started("check", "--world", str(world), "--rule-seconds", "200")
    wait_for(proc.stderr, "loaded", proc)
    time.sleep(0.5)                                    # into the check's episodes
    t0 = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert time.monotonic() - t0 < 5, err
    assert proc.returncode == 130 and "Traceback" not in err, err


# ---- I: relrl experiment worlds takes its options as given -----------------------------------

@pytest.mark.parametrize("argv, needle", [
    (["--episodes", "0"], "--episodes must be at least 1, not 0"),
    (["--block", "0"], "--block must be at least 1, not 0"),
    (["--eval-episodes", "0"], "--eval-episodes must be at least 1, not 0"),
    (["--seeds="], "--seeds"),
    (["--worlds", f"{BLOCKS},{BLOCKS}"], "--worlds names blocks.pl twice"),
    (["--tasks", "stack,stack"], "--tasks names stack twice"),
    (["--learners", "tg,tg"], "--learners names tg twice"),
])
def test_experiment_worlds_options_are_errors_not_defaults(capsys, tmp_path: Path,
                                                           argv: list[str],
                                                           needle: str) -> None:
    from tests.cli.conftest import one_line_exit_2

    one_line_exit_2(capsys, ["experiment", "worlds", *argv, "--out", str(tmp_path / "o")],
                    needle)
    assert not (tmp_path / "o").exists()


def test_experiment_worlds_quick_runs_tg_alone() -> None:
    """--quick is tg, seed 0 (its help says so); a learner given is kept."""
    import argparse

    from relrl.cli.experiment import add_arguments, build_worlds_config

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    quick = build_worlds_config(parser.parse_args(["worlds", "--quick", "--worlds",
                                                   str(BLOCKS), "--tasks", "stack"]))
    assert (quick.learners, quick.seeds, quick.episodes, quick.block) == (["tg"], [0], 200, 50)
    given = build_worlds_config(parser.parse_args(["worlds", "--quick", "--worlds",
                                                   str(BLOCKS), "--tasks", "stack",
                                                   "--learners", "ptg", "--episodes", "7"]))
    assert (given.learners, given.episodes) == (["ptg"], 7)
