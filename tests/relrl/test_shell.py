"""``relrl shell``: queries print like the swipl top level; commands; piped input."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from relrl.kb import KnowledgeBase
from relrl.shell import Shell
from tests.conftest import FRUITS, ROOT


@pytest.fixture
def shell():
    kb = KnowledgeBase(FRUITS)
    out = io.StringIO()
    sh = Shell(kb, out, timeout=0.5)
    yield sh, out
    kb.close()


def test_query_prints_bindings(shell) -> None:
    sh, out = shell
    sh.run_lines(["stimulus(S).\n"])
    assert out.getvalue() == ("S = face ;\nS = object ;\nS = attention ;\n"
                              "S = environment.\n")


def test_multi_line_query_and_compound_bindings(shell) -> None:
    sh, out = shell
    sh.run_lines(["fact(F),\n", "  F = looking_fruit(X).\n"])
    assert out.getvalue() == "F = looking_fruit(object),\nX = object.\n"


def test_true_and_false(shell) -> None:
    sh, out = shell
    sh.run_lines(["stimulus(face).\n", "stimulus(dog).\n"])
    assert out.getvalue() == "true.\nfalse.\n"


def test_percepts_memory_state(shell) -> None:
    sh, out = shell
    sh.run_lines([":add see(face), pose(face, frontal)\n", ":memory\n", ":state\n",
                  "see(frontal(face)).\n"])
    text = out.getvalue()
    assert "inserted 2 elements" in text
    assert "age 0   pose(face,frontal)" in text
    assert "state 129" in text
    assert text.endswith("true.\n")


def test_errors_do_not_stop_the_shell(shell) -> None:
    sh, out = shell
    sh.run_lines(["repeat, fail.\n", "foo(.\n", ":nope\n", "stimulus(face).\n"])
    text = out.getvalue()
    assert "error: query ran longer than 0.5 s" in text
    assert "Syntax error" in text
    assert "unknown command :nope" in text
    assert text.endswith("true.\n")
    assert sh.errors == 3


def test_quit_stops(shell) -> None:
    sh, out = shell
    sh.run_lines([":quit\n", "stimulus(face).\n"])
    assert out.getvalue() == ""


def test_piped_shell_process() -> None:
    proc = subprocess.run([sys.executable, "-m", "relrl.cli", "shell", str(FRUITS)],
                          input="response(R).\n", capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[0] == "R = look(centre) ;"
    assert proc.stdout.splitlines()[-1] == "R = name_object."
