"""Eq. 1 and 2, the mediator, and the sign convention of satisfiers."""

from __future__ import annotations

import math

import pytest

from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent
from tests.conftest import FRUITS


def sigmoid(x: float) -> float:
    return 1.0 / (1.0 + math.exp(-x))


@pytest.fixture
def agent():
    kb = KnowledgeBase(FRUITS)
    yield Agent(kb, make_learner("qlearning"), seed=0)
    kb.close()


def test_equations_by_hand(agent: Agent) -> None:
    # No contact: u = b + w_r * y_prev, y = sigma(u + delta); y_prev starts at 0.
    y1 = agent.step([]).outputs["socialize"]
    assert y1 == pytest.approx(sigmoid(1.0 + 0.0 + 0.2), abs=1e-12)
    y2 = agent.step([]).outputs["socialize"]
    assert y2 == pytest.approx(sigmoid(1.0 + 1.0 * y1 + 0.2), abs=1e-12)
    # Attention, a frontal face and looking at it: all three satisfiers subtract.
    out = agent.step([("hear", "attention"), ("see", "face"), ("pose", "face", "frontal"),
                      ("at", "centre")])
    u = 1.0 + y2 - 1.5 - 0.95 - 0.5
    assert out.outputs["socialize"] == pytest.approx(sigmoid(u + 0.2), abs=1e-12)


def test_mediator_threshold(agent: Agent) -> None:
    assert agent.step([]).necessity == "socialize"  # 0.769 > 0.5
    contact = [("hear", "attention"), ("see", "face"), ("pose", "face", "frontal"),
               ("at", "centre")]
    necessities = [agent.step(contact).necessity for _ in range(5)]
    assert necessities[-1] == "none"


def test_socialize_rises_without_contact_and_falls_with_attention(agent: Agent) -> None:
    alone = [agent.step([]).outputs["socialize"] for _ in range(10)]
    assert all(b > a for a, b in zip(alone, alone[1:], strict=False))
    assert alone[-1] > 0.85
    contact = [("hear", "attention"), ("see", "face"), ("pose", "face", "frontal"),
               ("at", "centre")]
    with_attention = [agent.step(contact).outputs["socialize"] for _ in range(10)]
    assert all(b < a for a, b in zip(with_attention, with_attention[1:], strict=False))
    assert with_attention[-1] < 0.5


def test_reward_from_reinforcer(agent: Agent) -> None:
    assert agent.step([("see", "face")]).reward == -1.0
    assert agent.step([("hear", "attention")]).reward == 10.0


def test_rewards_are_configurable() -> None:
    with KnowledgeBase(FRUITS) as kb:
        agent = Agent(kb, make_learner("etg", reward_positive=1.0, reward_negative=0.0))
        assert agent.step([("hear", "attention")]).reward == 1.0
        assert agent.step([]).reward == 0.0
