"""Prolog text nested some 20,000 deep, through every way it reaches the embedded engine:
an error as plain swipl gives it (its C-stack guard), never a crash of the process.

Regression: reading it crashed the process (exit 139, a segmentation fault): SWI-Prolog ran
without its signal handlers, so a C stack overflow in the reader was not caught."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from relrl.errors import PolicyError
from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent
from tests.conftest import FRUITS, ROOT

pytestmark = pytest.mark.slow  # every test here takes a second or more

DEPTH = 20_000
DEEP = "f(" * DEPTH + "a" + ")" * DEPTH


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("deep")
    with KnowledgeBase(FRUITS) as kb:
        agent = Agent(kb, make_learner("etg"), seed=0)
        for _ in range(5):
            agent.step([("see", "face")])
        policy = agent.learner.save(folder / "policy.pl")
    deep_policy = folder / "deep_policy.pl"
    deep_policy.write_text(policy.read_text() + f"etg_node(99, {DEEP}).\n")
    deep_domain = folder / "deep_domain.pl"
    deep_domain.write_text(FRUITS.read_text() + f"deep({DEEP}).\n")
    return {"policy": deep_policy, "domain": deep_domain}


def _relrl(*args: str, stdin: str = "") -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "relrl.cli", *args], input=stdin,
                          capture_output=True, text=True, cwd=ROOT, timeout=300)


def _one_clean_error(proc: subprocess.CompletedProcess, text: str) -> None:
    assert proc.returncode == 2, (proc.returncode, proc.stderr[-2000:])
    out = proc.stdout + proc.stderr
    assert text in out and "Traceback" not in out


def test_a_domain(files: dict[str, Path]) -> None:
    _one_clean_error(_relrl("check", str(files["domain"])), "C-stack limit")


def test_a_policy_drawn(files: dict[str, Path], tmp_path: Path) -> None:
    proc = _relrl("tree", "--domain", str(FRUITS), str(files["policy"]),
                  "--out", str(tmp_path / "t.svg"))
    _one_clean_error(proc, "deep_policy.pl: a term nested too deep to read")


def test_a_policy_in_the_shell(files: dict[str, Path]) -> None:
    proc = _relrl("shell", str(FRUITS), "--policy", str(files["policy"]))
    _one_clean_error(proc, "deep_policy.pl: a term nested too deep to read")


def test_a_policy_loaded(files: dict[str, Path]) -> None:
    """What an episode's ``policy_load`` does."""
    with KnowledgeBase(FRUITS) as kb:
        agent = Agent(kb, make_learner("etg"), seed=0)
        with pytest.raises(PolicyError, match="nested too deep to read"):
            agent.learner.load(files["policy"])
        assert kb.holds(("stimulus", "face"))          # the engine goes on


@pytest.mark.parametrize("line", [f"X = {DEEP}.", f":add see({DEEP})"])
def test_piped_to_the_shell(line: str) -> None:
    proc = _relrl("shell", str(FRUITS), stdin=f"{line}\nstimulus(face).\n")
    assert proc.returncode == 2 and "Traceback" not in proc.stdout + proc.stderr
    lines = proc.stdout.splitlines()
    assert "C-stack limit" in lines[0] and lines[-1] == "true."
