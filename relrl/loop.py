"""The control loop: perceive -> working memory -> state -> motivation -> choose -> emit ->
observe -> learn.

:class:`Agent` is the robot's mind over one knowledge base and one learner: each
:meth:`Agent.step` is one gateway call into Prolog (plus the learner's own work when it keeps
its numbers in Python). :func:`run` drives an :class:`~relrl.interfaces.Environment` and an
optional :class:`~relrl.interfaces.Actuator` with an agent.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from relrl.errors import UserError
from relrl.interfaces import Actuator, Environment
from relrl.kb import KnowledgeBase
from relrl.learners.base import Learner, StepOut
from relrl.terms import Term, Var

__all__ = ["Agent", "StepRecord", "run"]


class Agent:
    """A knowledge base, a learner and the memory of what was emitted last.

    Args:
        kb: the knowledge base holding the domain.
        learner: the learner (see :func:`relrl.learners.make_learner`).
        seed: seeds Prolog's and the learner's random numbers: same seed, same run.
    """

    def __init__(self, kb: KnowledgeBase, learner: Learner, *, seed: int | None = 0) -> None:
        self.kb = kb
        self.learner = learner
        self.seed = seed
        learner.attach(kb, seed)
        (responses,) = kb.call("relrl_engine:engine_responses", kb.module, Var())
        self.responses: list[Term] = responses
        (names,) = kb.call("relrl_gateway:gw_findall", kb.module, ("necessity", Var()), Var())
        self.necessities: list[str] = [n[1] for n in names]
        self._emitted = -1
        self.emitted: Term = "none"
        self.steps = 0
        self.states: set[int] = set()

    def step(self, percepts: Sequence[Term], *, learning: bool = True) -> StepOut:
        """One control step from this time unit's percepts; returns what happened and the
        response to emit (``out.action``)."""
        (raw,) = self.kb.call("relrl_engine:engine_step", self.kb.module, list(percepts),
                              self._emitted, "true" if learning else "false", Var())
        _, code, necessity, ys, reward, allowed, action = raw
        responses = self.responses
        out = StepOut(code, necessity, dict(zip(self.necessities, ys, strict=True)), reward,
                      [responses[i] for i in allowed], responses[action] if action >= 0 else "none")
        out.extra["allowed_index"] = allowed
        out.action = self.learner.act(out, learning)
        self.emitted = out.action
        self._emitted = self._index_of(out.action)
        self.steps += 1
        self.states.add(code)
        return out

    def _index_of(self, action: Term) -> int:
        if action == "none":
            return -1
        try:
            return self.responses.index(action)
        except ValueError:
            raise UserError(f"the learner chose {action!r}, which is not a declared "
                            "response") from None

    def end_episode(self) -> None:
        """End an interaction: forget the last step and working memory."""
        self.kb.call("relrl_engine:engine_end_episode", self.kb.module)
        self.learner.end_episode()
        self.emitted = "none"
        self._emitted = -1


@dataclass
class StepRecord:
    """One time unit of a run, as the loop saw it."""

    t: int
    percepts: list[Term]
    out: StepOut
    env_reward: float
    info: dict[str, Any]


def run(env: Environment, agent: Agent, steps: int, *, learning: bool = True,
        actuator: Actuator | None = None, seed: int | None = None,
        on_step: Callable[[StepRecord], None] | None = None,
        reset: bool = True) -> list[StepRecord]:
    """Run ``steps`` time units of ``env`` with ``agent``.

    The robot perceives, its mind steps (one gateway call), the response goes to the
    actuator (if any) and to the environment, which advances one time unit.

    Returns:
        the records of every step (also passed to ``on_step`` as they happen).
    """
    records: list[StepRecord] = []
    if reset:
        _, info = env.reset(seed=seed)
    else:
        info = getattr(env, "last_info", {"percepts": []})
    for t in range(steps):
        percepts = info["percepts"]
        out = agent.step(percepts, learning=learning)
        if out.action != "none" and actuator is not None:
            actuator.emit(out.action)
        _, env_reward, terminated, truncated, info = env.step(out.action)
        record = StepRecord(t, percepts, out, env_reward, info)
        records.append(record)
        if on_step is not None:
            on_step(record)
        if terminated or truncated:
            agent.end_episode()
            _, info = env.reset()
    return records
