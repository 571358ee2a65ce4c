"""The tree as the monitor draws it: the legend of the leaves says what the learners' own
labels hold, an empty leaf says it is empty, and the page gets the names and parents it marks
a path with."""

from __future__ import annotations

import re

import pytest

from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent, run
from relrl.monitor.graph import EMPTY_LEAF, LEAF_LEGENDS, picture, to_dot
from tests.conftest import ROOT
from tests.relrl.tasks import LightDark

#: what a line of each learner's labels looks like, as LEAF_LEGENDS describes it.
LEAF_LINE = {"etg": re.compile(r"\S+ -?\d+\.\d\d \[\w+\]"),
             "tg": re.compile(r"Q=-?\d+\.\d\d \(n=\d+\)")}


def _leaf_lines(graph: dict) -> list[str]:
    return [line for n in graph["nodes"] if n["kind"] == "leaf"
            for line in n["label"].splitlines()]


def test_the_etg_legend_says_what_its_leaves_hold() -> None:
    with KnowledgeBase(ROOT / "tests" / "data" / "tiny.pl") as kb:
        agent = Agent(kb, make_learner("etg", split_threshold=1.0), seed=0)
        run(LightDark(), agent, 300, seed=0)
        graph = agent.learner.graph()
    lines = _leaf_lines(graph)
    assert len(lines) >= 2
    assert all(LEAF_LINE["etg"].fullmatch(line) for line in lines), lines
    assert LEAF_LINE["etg"].fullmatch(LEAF_LEGENDS["etg"][0]["example"])
    assert any(n["kind"] == "test" for n in graph["nodes"])


@pytest.mark.slow
def test_the_tg_legend_says_what_its_leaves_hold() -> None:
    from tests.relrl.test_tg import trained

    agent = trained(steps=300)
    graph = agent.learner.graph()
    agent.kb.close()
    lines = _leaf_lines(graph)
    assert lines and all(LEAF_LINE["tg"].fullmatch(line) for line in lines), lines
    assert LEAF_LINE["tg"].fullmatch(LEAF_LEGENDS["tg"][0]["example"])


def test_an_empty_leaf_says_so() -> None:
    source = to_dot({"nodes": [{"id": "0", "kind": "leaf", "label": ""}], "edges": []}).source
    assert EMPTY_LEAF in source


def test_the_picture_names_each_node_and_its_parent() -> None:
    graph = {"nodes": [{"id": 7, "kind": "test", "label": "t"},
                       {"id": "a", "kind": "leaf", "label": "x 1.00 [none]"},
                       {"id": 9, "kind": "test", "label": "u"},
                       {"id": 10, "kind": "leaf", "label": "y 2.00 [none]"}],
             "edges": [{"from": 7, "to": "a", "branch": "yes"},
                       {"from": 7, "to": 9, "branch": "no"},
                       {"from": 9, "to": 10, "branch": "yes"},
                       {"from": 9, "to": "nowhere", "branch": "no"}]}
    drawn = picture(graph)
    assert drawn.names == {"7": "n0", "a": "n1", "9": "n2", "10": "n3"}
    assert drawn.parents == {"n1": "n0", "n2": "n0", "n3": "n2"}
    svg = drawn.svg.decode()
    for name in drawn.names.values():
        assert f"<title>{name}</title>" in svg
    assert "<title>n2&#45;&gt;n3</title>" in svg  # the edge the page marks as n2->n3
