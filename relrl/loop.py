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
from relrl.kb import Cached, KnowledgeBase
from relrl.learners.base import Learner, StepOut
from relrl.terms import Term, Var

__all__ = ["Agent", "Interaction", "StepRecord", "run"]


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

    def step(self, percepts: Sequence[Term], *, learning: bool = True,
             explore: bool | None = None) -> StepOut:
        """One control step from this time unit's percepts; returns what happened and the
        response to emit (``out.action``).

        Args:
            percepts: this time unit's perception facts.
            learning: update the learner from the previous step.
            explore: keep the learner's exploration (epsilon); by default only when learning.
                Evaluating with ``learning=False, explore=True`` measures the behaviour the
                robot shows, without changing what it knows.
        """
        if explore is None:
            explore = learning
        mode = "true" if learning else ("explore" if explore else "false")
        (raw,) = self.kb.call("relrl_engine:engine_step", self.kb.module,
                              Cached(percepts if isinstance(percepts, list) else list(percepts)),
                              self._emitted, mode, Var())
        _, code, necessity, ys, reward, mask, action = raw
        responses = self.responses
        allowed = [i for i in range(len(responses)) if mask >> i & 1]
        out = StepOut(code, necessity, dict(zip(self.necessities, ys, strict=True)), reward,
                      [responses[i] for i in allowed], responses[action] if action >= 0 else "none",
                      allowed)
        out.action = self.learner.act(out, learning, explore)
        self.emitted = out.action
        self._emitted = self._index_of(out.action)
        self.steps += 1
        self.states.add(code)
        return out

    def save_random(self) -> Any:
        """Save the state of every random stream the agent draws from (Prolog's, the
        learner's); :meth:`restore_random` puts it back."""
        self.kb.call("relrl_engine:engine_save_random", self.kb.module)
        return self.learner.rng.bit_generator.state

    def restore_random(self, saved: Any) -> None:
        """Restore the random streams saved by :meth:`save_random`."""
        self.kb.call("relrl_engine:engine_restore_random", self.kb.module)
        self.learner.rng.bit_generator.state = saved

    def reseed(self, seed: int) -> None:
        """Seed every random stream the agent draws from."""
        import numpy as np

        self.kb.call("relrl_engine:engine_set_random", ("seed", int(seed)))
        self.learner.rng = np.random.default_rng(int(seed))

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


class Interaction:
    """An agent interacting with an environment (and, optionally, a real actuator).

    The robot perceives, its mind steps (one gateway call), the response goes to the
    actuator (if any) and to the environment, which advances one time unit. Learning and
    evaluation phases can alternate on the same interaction (:meth:`run` continues where the
    last call stopped).

    Args:
        env: the environment (simulator, scripted episode, camera).
        agent: the robot's mind.
        actuator: what carries the responses out besides the environment (a head).
        on_step: called with every :class:`StepRecord` as it happens.
    """

    def __init__(self, env: Environment, agent: Agent, *, actuator: Actuator | None = None,
                 on_step: Callable[[StepRecord], None] | None = None) -> None:
        self.env = env
        self.agent = agent
        self.actuator = actuator
        self.on_step = on_step
        self.info: dict[str, Any] | None = None
        self.t = 0

    def reset(self, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> dict[str, Any]:
        """Start a new interaction: the environment resets, the agent ends its episode."""
        self.agent.end_episode()
        _, self.info = self.env.reset(seed=seed, options=options)
        return self.info

    def run(self, steps: int, *, learning: bool = True, explore: bool | None = None,
            keep: bool = True) -> list[StepRecord]:
        """Run ``steps`` time units; returns their records (none when ``keep`` is False).

        ``learning`` and ``explore`` are as in :meth:`Agent.step`."""
        if self.info is None:
            self.reset()
        assert self.info is not None
        records: list[StepRecord] = []
        agent, env, actuator, on_step = self.agent, self.env, self.actuator, self.on_step
        info = self.info
        for _ in range(steps):
            percepts = info["percepts"]
            out = agent.step(percepts, learning=learning, explore=explore)
            if actuator is not None and out.action != "none":
                actuator.emit(out.action)
            _, env_reward, terminated, truncated, info = env.step(out.action)
            self.info = info
            if keep or on_step is not None:
                record = StepRecord(self.t, percepts, out, env_reward, info)
                if keep:
                    records.append(record)
                if on_step is not None:
                    on_step(record)
            self.t += 1
            if terminated or truncated:
                info = self.reset()
        return records


def run(env: Environment, agent: Agent, steps: int, *, learning: bool = True,
        actuator: Actuator | None = None, seed: int | None = None,
        on_step: Callable[[StepRecord], None] | None = None) -> list[StepRecord]:
    """Reset ``env`` with ``seed`` and run ``steps`` time units of it with ``agent``.

    Returns:
        the records of every step (also passed to ``on_step`` as they happen).
    """
    interaction = Interaction(env, agent, actuator=actuator, on_step=on_step)
    interaction.reset(seed=seed)
    return interaction.run(steps, learning=learning)
