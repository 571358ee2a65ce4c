"""The engine's speed work changes no decision (issue 13, item 4).

tests/data/golden_decisions.json was recorded before the speed work: for each learner, a
3,000-step percept stream from a closed-loop run on the simulator, and the choices, the
`socialize` unit's outputs and the final memory the engine produced replaying that stream
open-loop from a fresh, seeded agent. Replaying it now must give exactly the same."""

from __future__ import annotations

import json

import pytest

from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent
from tests.conftest import ROOT

pytestmark = pytest.mark.slow  # every test here takes a second or more

GOLDEN = json.loads((ROOT / "tests" / "data" / "golden_decisions.json").read_text())


def _term(value: object) -> object:
    return tuple(_term(v) for v in value) if isinstance(value, list) else value


@pytest.mark.parametrize("learner", sorted(GOLDEN["runs"]))
def test_replayed_stream_gives_the_recorded_decisions(learner: str) -> None:
    run = GOLDEN["runs"][learner]
    percepts = [_term(p) for p in GOLDEN["percepts"]]
    with KnowledgeBase(ROOT / GOLDEN["domain"]) as kb:
        agent = Agent(kb, make_learner(learner), seed=run["seed"])
        actions, outputs = [], []
        for emitted, *indices in run["stream"]:
            agent._emitted = emitted          # replay what was emitted, open loop
            out = agent.step([percepts[i] for i in indices])
            actions.append(str(agent.responses.index(out.action)))
            outputs.append(round(out.outputs["socialize"], 12))
        assert "".join(actions) == run["actions"]
        assert outputs == run["socialize"]
        assert agent.learner.size() == run["size"]
