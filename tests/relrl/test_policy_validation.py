"""A policy is checked as a whole before it is used: a refused one changes nothing; a good
one loads back as it was saved; its values can learn without overflow; loading and saving
take time in proportion to its size, not the time limit of one rule (prolog/policy.pl,
the learners' restore hooks, relrl/learners/qlearning.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from relrl.errors import PolicyError
from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent
from tests.conftest import FRUITS, ROOT

TINY = ROOT / "tests" / "data" / "tiny.pl"
STREAM = ([("see", "light")], [("see", "dark")], [("see", "light"), ("smell", "food")],
          [("see", "dark"), ("smell", "food")], [("see", "light")])


def _trained(kb: KnowledgeBase, name: str, **params: float) -> Agent:
    agent = Agent(kb, make_learner(name, **params), seed=0)
    for _ in range(3):
        for percepts in STREAM:
            agent.step(percepts)
    return agent


def _text(agent: Agent) -> str:
    learner = agent.learner
    if learner.name == "qlearning":
        return repr(learner.explain(now=True)) + repr(learner.size())
    return learner.engine.text()


@pytest.mark.parametrize("name, bad", [
    ("etg", "etg_node(0, leaf(none, [e(halt, 1.0, hunger)])).\n"),
    ("contingency", "learned_behaviour(state(1), a, hunger, 1.0Inf).\n"),
])
def test_a_refused_policy_leaves_what_was_learned(tmp_path: Path, name: str, bad: str) -> None:
    with KnowledgeBase(TINY) as kb:
        agent = _trained(kb, name)
        good = agent.learner.save(tmp_path / "good.pl")
        before = _text(agent)
        text = good.read_text()
        cut = text.index("etg_node(") if name == "etg" else len(text)
        (tmp_path / "bad.pl").write_text(text[:cut] + bad)
        with pytest.raises(PolicyError, match=r"bad\.pl:\d+: "):
            agent.learner.load(tmp_path / "bad.pl")
        assert _text(agent) == before


def test_a_refused_q_table_leaves_what_was_learned(tmp_path: Path) -> None:
    with KnowledgeBase(TINY) as kb:
        agent = _trained(kb, "qlearning")
        good = agent.learner.save(tmp_path / "good.npz")
        before = _text(agent)
        with np.load(good) as table:
            arrays = {k: table[k] for k in table.files}
        arrays["q"] = np.where(arrays["q"] == arrays["q"].max(), np.nan, arrays["q"])
        np.savez(tmp_path / "bad.npz", **arrays)
        with pytest.raises(PolicyError, match=r"bad\.npz: row \d+: the Q of . is nan"):
            agent.learner.load(tmp_path / "bad.npz")
        assert _text(agent) == before


@pytest.mark.parametrize("name", ["etg", "contingency", "tg"])
def test_a_policy_loads_back_as_it_was_saved(tmp_path: Path, name: str) -> None:
    domain = ROOT / "tests" / "data" / "tg_gaze.pl" if name == "tg" else TINY
    stream = [[("pose", "face", p)] for p in ("p1", "p2", "p3", "p4")] * 6 if name == "tg" \
        else list(STREAM) * 3
    with KnowledgeBase(domain) as kb:
        agent = Agent(kb, make_learner(name), seed=0)
        for percepts in stream:
            agent.step(percepts)
        first = agent.learner.save(tmp_path / "first.pl")
        fresh = Agent(kb, make_learner(name), seed=0)
        fresh.learner.load(first)
        second = fresh.learner.save(tmp_path / "second.pl")
        assert second.read_text() == first.read_text()


def test_a_leafs_entries_are_put_in_decreasing_q(tmp_path: Path) -> None:
    with KnowledgeBase(TINY) as kb:
        agent = _trained(kb, "etg")
        text = agent.learner.save(tmp_path / "p.pl").read_text()
        head = text[:text.index("etg_node(")]
        (tmp_path / "edited.pl").write_text(
            head + "etg_node(0, leaf(none, [e(a, 1.0, hunger), e(b, 5.0, hunger)])).\n")
        agent.learner.load(tmp_path / "edited.pl")
        ranked = agent.learner.explain(now=True)["ranked"]
        assert [r["response"] for r in ranked] == ["b", "a"]


@pytest.mark.parametrize("q", ["1.0e15", "-1.0e15", "1000000000000000"])
def test_the_largest_values_learn_without_overflow(tmp_path: Path, q: str) -> None:
    """A policy's values are at most 1e15 in magnitude: far from overflowing at an update
    (a Q of 1e308, or of 400 digits, used to overflow at the first one)."""
    with KnowledgeBase(TINY) as kb:
        agent = _trained(kb, "etg", q_init=0.0)
        text = agent.learner.save(tmp_path / "p.pl").read_text()
        head = text[:text.index("etg_node(")]
        (tmp_path / "big.pl").write_text(
            head + f"etg_node(0, leaf(none, [e(a, {q}, hunger), e(b, {q}, hunger), "
                   f"e(c, {q}, hunger)])).\n")
        agent.learner.load(tmp_path / "big.pl")
        for percepts in STREAM * 4:
            agent.step(percepts)
        agent.learner.save(tmp_path / "after.pl")
        (tmp_path / "edge.pl").write_text(
            head + "etg_node(0, leaf(none, [e(a, 1.0000001e15, hunger)])).\n")
        with pytest.raises(PolicyError, match=r"edge\.pl:\d+: leaf 0: the Q of a "
                                              r"1.0000001e\+15 is out of range"):
            agent.learner.load(tmp_path / "edge.pl")


@pytest.mark.slow
def test_loading_and_saving_take_time_in_proportion_to_the_policy(tmp_path: Path) -> None:
    """A 5 MB policy loads and saves under a knowledge base whose time limit (0.5 s) is far
    shorter than reading it takes: no rule of the policy runs, its size bounds the work
    (it used to end in "query ran longer than ..." naming no file)."""
    responses = ["look(centre)", "look(left)", "look(left_down)", "look(down)",
                 "look(right_down)", "look(right)", "name_object"]
    with KnowledgeBase(FRUITS, timeout=0.5) as kb:
        agent = Agent(kb, make_learner("contingency"), seed=0)
        text = agent.learner.save(tmp_path / "empty.pl").read_text()
        rules = [f"learned_behaviour(state({code}), {r}, {n}, 0.5).\n"
                 for code in range(7000) for n in ("socialize", "none") for r in responses]
        big = tmp_path / "big.pl"
        big.write_text(text + "".join(rules))
        assert big.stat().st_size > 5e6
        authored = text.count("learned_behaviour(")     # the domain's own rules
        agent.learner.load(big)
        assert agent.learner.size()["positions"] == authored + len(rules)
        again = agent.learner.save(tmp_path / "again.pl")
        assert again.read_text().count("learned_behaviour(") == authored + len(rules)


@pytest.mark.parametrize("change, message", [
    ({"codes": ["-1", "1"]}, r"row 0: state '-1' is not a state code"),
    ({"codes": ["8", "1"]}, r"row 0: state '8' is not a state code of this domain "
                            r"\(0 to 2\^3 - 1\)"),
    ({"necessities": ["<script>", "hunger"]}, r"row 0: '<script>' is not a necessity"),
    ({"codes": ["1", "1"], "necessities": ["hunger", "hunger"]},
     r"rows 0 and 1 are both state 1 under hunger"),
    ({"q": "complex"}, r"not a relrl Q-table \(.npz\): array 'q' holds complex128"),
    ({"q": "huge"}, r"the Q of a is 1e\+300"),
    ({"rows": 100}, r"100 rows, more than the domain's 16"),
    ({"responses": ["a", "b", "halt"]}, r"learned for another domain"),
])
def test_a_q_table_is_checked_as_a_whole(tmp_path: Path, change: dict, message: str) -> None:
    with KnowledgeBase(TINY) as kb:
        agent = Agent(kb, make_learner("qlearning"), seed=0)
        for percepts in ([("see", "light")], [("see", "dark")], [("see", "light")]):
            agent.step(percepts)
        with np.load(agent.learner.save(tmp_path / "good.npz")) as table:
            arrays = {k: table[k] for k in table.files}
        assert len(arrays["codes"]) == 2
        for key, value in change.items():
            if key == "rows":
                arrays.update(q=np.zeros((value, 3)), codes=np.array(["0"] * value),
                              necessities=np.array(["none"] * value))
            elif value == "complex":
                arrays["q"] = arrays["q"].astype(complex)
            elif value == "huge":
                arrays["q"] = np.full_like(arrays["q"], 1e300)
            else:
                arrays[key] = np.array(value)
        np.savez(tmp_path / "bad.npz", **arrays)
        with pytest.raises(PolicyError, match=message):
            agent.learner.load(tmp_path / "bad.npz")
