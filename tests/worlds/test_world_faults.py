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
