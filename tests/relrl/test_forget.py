"""A dropped knowledge base leaves nothing behind: 500 create/step/drop cycles per learner
in one long-lived process (an experiment worker's life), resident memory flat after the
first 20 cycles, and no module, global or clause of a dropped knowledge base left.

The cycles run in a process of their own (tests/relrl/forget_cycles.py), so that this test
process's other knowledge bases do not blur the measure.
"""

from __future__ import annotations

import json
import subprocess
import sys
from typing import Any

import pytest

from relrl.kb import KnowledgeBase
from tests.conftest import ROOT, SIS

CYCLES = 500
WARM_UP = 20            #: cycles before the measure starts (caches, the learners' code)
GROWTH_KB = 2048        #: at most this much resident memory growth after the warm-up
#: every learner of the simulator's domain, and the worlds' learners (episodes of a world)
LEARNERS = ("contingency", "qlearning", "etg", "tg", "qtable-world", "tg-world", "ptg-world")


@pytest.fixture(scope="module")
def cycles() -> dict[str, dict[str, Any]]:
    """Each learner's figures, from one process that runs them one after the other."""
    proc = subprocess.run(
        [sys.executable, "-m", "tests.relrl.forget_cycles", str(CYCLES), "2", *LEARNERS],
        capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    figures = [json.loads(line) for line in proc.stdout.splitlines()]
    return {f["learner"]: f for f in figures}


@pytest.mark.parametrize("learner", LEARNERS)
@pytest.mark.slow
def test_dropped_knowledge_bases_leave_nothing(cycles: dict[str, dict[str, Any]],
                                               learner: str) -> None:
    figures = cycles[learner]
    rss = figures["rss_kb"]
    assert len(rss) == CYCLES
    assert rss[-1] - rss[WARM_UP - 1] <= GROWTH_KB, (
        f"{learner}: resident memory grew {rss[-1] - rss[WARM_UP - 1]} KiB over "
        f"{CYCLES - WARM_UP} create/step/drop cycles")
    assert figures["left_module"] == "[]", figures["module"]
    assert figures["left_globals"] == "[]"
    assert figures["left_clauses"] == "[]"


def test_dropping_a_knowledge_base_leaves_the_libraries_it_loaded(tmp_path) -> None:
    """A domain's use_module/1 of a library loaded before (lists) or by it alone (ugraphs):
    dropping its knowledge base unloads the domain, never the libraries others use."""
    domain = tmp_path / "d.pl"
    domain.write_text(SIS.read_text() + ":- use_module(library(lists)).\n"
                      ":- use_module(library(ugraphs)).\n"
                      "edges(E) :- vertices_edges_to_ugraph([a, b], [a-b], G), edges(G, E).\n")
    for _ in range(2):
        with KnowledgeBase(domain) as kb:
            assert kb.query("edges(E)")[0][0][0][2] == "[a-b]"
    with KnowledgeBase(SIS) as kb:
        solutions, _ = kb.query("lists:member(x, [x]), ugraphs:vertices_edges_to_ugraph([], [], G)")
        assert solutions == [[("G", [], "[]")]]
