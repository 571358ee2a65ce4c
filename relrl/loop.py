"""The control loop: perceive -> working memory -> state -> motivation -> choose -> emit ->
observe -> learn.

:class:`Agent` is the robot's mind over one knowledge base and one learner: each
:meth:`Agent.step` is one gateway call into Prolog (plus the learner's own work when it keeps
its numbers in Python). :func:`run` drives an :class:`~relrl.interfaces.Environment` and an
optional :class:`~relrl.interfaces.Actuator` with an agent.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from relrl.engine import ALL_ALLOWED, Engine, mask_indices
from relrl.errors import UserError
from relrl.interfaces import Actuator, Environment
from relrl.kb import KnowledgeBase
from relrl.learners.base import Learner, StepOut
from relrl.terms import Term

__all__ = ["Agent", "Interaction", "StepRecord", "run"]


class Agent:
    """A knowledge base, a learner and the memory of what was emitted last.

    Args:
        kb: the knowledge base holding the domain.
        learner: the learner (see :func:`relrl.learners.make_learner`).
        seed: seeds the agent's own random streams (its knowledge base's Prolog stream and
            the learner's numpy generator): same seed, same run, whatever other agents in
            the process do. None seeds them from the clock.
    """

    def __init__(self, kb: KnowledgeBase, learner: Learner, *, seed: int | None = 0) -> None:
        self.kb = kb
        self.learner = learner
        self.seed = seed
        self.engine = Engine(kb)
        learner.attach(self.engine, seed)
        self.responses: list[Term] = self.engine.responses
        self.necessities: list[str] = self.engine.necessities
        self._emitted = -1
        self.emitted: Term | None = None
        self._allowed: dict[int, tuple[tuple[int, ...], tuple[Term, ...]]] = {}
        self.steps = 0
        self.states: set[int] = set()

    def step(self, percepts: Sequence[Term], *, learning: bool = True,
             explore: bool | None = None, want: Iterable[str] = ()) -> StepOut:
        """One control step from this time unit's percepts; returns what happened and the
        response to emit (``out.action``, None when nothing is allowed).

        Args:
            percepts: this time unit's perception facts.
            learning: update the learner from the previous step.
            explore: keep the learner's exploration (epsilon); by default only when learning.
                Evaluating with ``learning=False, explore=True`` measures the behaviour the
                robot shows, without changing what it knows.
            want: what else to report from the same gateway call: ``"memory"`` (working
                memory with ages), ``"memory_size"``, ``"explain"`` (the learner's
                explanation of this step's choice).
        """
        if explore is None:
            explore = learning
        mode = "learn" if learning else ("explore" if explore else "greedy")
        (code, necessity, ys, reward, reinforced, mask, action_index, memory, memory_size,
         explanation) = self.engine.step_fields(percepts, self._emitted, mode, want)
        responses = self.responses
        allowed_index, allowed = self._allowed.get(mask) or self._allow(mask)
        action = responses[action_index] if action_index >= 0 else None
        out = StepOut(code, necessity, dict(zip(self.necessities, ys, strict=True)), reward,
                      list(allowed), action, list(allowed_index), reinforced=reinforced,
                      memory=memory, memory_size=memory_size)
        out.action = self.learner.act(out, learning, explore)
        if explanation is not None:
            out.explanation = self.learner.decode_explanation(explanation)
        self.emitted = out.action
        if out.action is None:
            self._emitted = -1
        elif action_index >= 0 and out.action is action:
            self._emitted = action_index      # the engine's own choice: its index
        else:
            self._emitted = self._index_of(out.action)
        self.steps += 1
        self.states.add(code)
        return out

    @contextlib.contextmanager
    def preserved(self) -> Iterator[Agent]:
        """Within the block the agent may act (an evaluation); on exit its working memory,
        necessity units, last step and every random stream are as they were, so what it
        learns afterwards does not depend on what was evaluated.

        The learned knowledge is not saved: act with ``learning=False`` inside."""
        slot = self.engine.keep()
        learner_state = self.learner.episode_state()
        emitted = (self._emitted, self.emitted)
        try:
            yield self
        finally:
            self.engine.resume(slot)
            self.learner.set_episode_state(learner_state)
            self._emitted, self.emitted = emitted

    def save_random(self) -> Any:
        """Save the state of every random stream the agent draws from (its knowledge
        base's, the learner's); :meth:`restore_random` puts it back. Prefer
        :meth:`preserved`, which saves the episode state as well."""
        return (self.engine.keep(), self.learner.rng.bit_generator.state)

    def restore_random(self, saved: Any) -> None:
        """Restore the random streams (and episode state) saved by :meth:`save_random`."""
        slot, state = saved
        self.engine.resume(slot)
        self.learner.rng.bit_generator.state = state

    def reseed(self, seed: int) -> None:
        """Seed every random stream the agent draws from."""
        import numpy as np

        self.engine.reseed(int(seed))
        self.learner.rng = np.random.default_rng(int(seed))

    def _allow(self, mask: int) -> tuple[tuple[int, ...], tuple[Term, ...]]:
        """The allowed responses' indices and terms for an allowed-mask (remembered: a
        domain has few masks; :data:`~relrl.engine.ALL_ALLOWED`: every response)."""
        index = range(len(self.responses)) if mask == ALL_ALLOWED else mask_indices(mask)
        pair = (tuple(index), tuple(self.responses[i] for i in index))
        if len(self._allowed) < 4096:
            self._allowed[mask] = pair
        return pair

    def _index_of(self, action: Term | None) -> int:
        if action is None:
            return -1
        try:
            return self.responses.index(action)
        except ValueError:
            raise UserError(f"the learner chose {action!r}, which is not a declared "
                            "response") from None

    def end_episode(self) -> None:
        """End an interaction: forget the last step and working memory."""
        self.engine.end_episode()
        self.learner.end_episode()
        self.emitted = None
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
            keep: bool = True, want: Iterable[str] = ()) -> list[StepRecord]:
        """Run ``steps`` time units; returns their records (none when ``keep`` is False).

        ``learning``, ``explore`` and ``want`` are as in :meth:`Agent.step` (what ``want``
        asks for arrives in each record's ``out`` from the step's one gateway call)."""
        want = tuple(want)
        if self.info is None:
            self.reset()
        assert self.info is not None
        records: list[StepRecord] = []
        agent, env, actuator, on_step = self.agent, self.env, self.actuator, self.on_step
        info = self.info
        for _ in range(steps):
            percepts = info["percepts"]
            out = agent.step(percepts, learning=learning, explore=explore, want=want)
            if actuator is not None and out.action is not None:
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
