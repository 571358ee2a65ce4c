"""An answer of any size crosses the bridge: SWI-Prolog's string buffers are released as
the answer is read (1.2 million atoms held them all: "Too many stacked strings", a fatal
abort that took the process and what it had learned with it)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT

SCRIPT = """
import sys
from relrl.kb import KnowledgeBase
from relrl.terms import Var
with KnowledgeBase() as kb:
    out = kb.call("findall", "b7", ("between", 1, int(sys.argv[1]), Var()), Var())
    print(len(out[0]), set(out[0]))
"""


@pytest.mark.slow
def test_an_answer_of_a_million_atoms_does_not_abort_prolog() -> None:
    """In a process of its own: the abort it guards against would end the test run."""
    proc = subprocess.run([sys.executable, "-c", SCRIPT, "1200000"], cwd=ROOT, text=True,
                          capture_output=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == ["1200000", "{'b7'}"]
