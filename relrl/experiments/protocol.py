"""One learner in one simulator world: learning blocks and evaluations that change nothing.

:class:`Session` is the shared core of Experiment 1 (:mod:`relrl.experiments.sis`) and the
scaling benchmark (:mod:`relrl.experiments.scaling`): a knowledge base with the world's
domain, an agent with its learner, a learning interaction that continues from block to block,
and evaluations by the paper's protocol (:func:`relrl.sim.evaluation.evaluate`).

Evaluation never changes the learner: it does not learn, and every random stream the agent
draws from is saved before and restored after, each run reseeded from its own seed. So
learning never depends on how much was evaluated, and run *k* gives the same numbers in
whichever process computes it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["Session", "codes_met", "point_summary"]


class Session:
    """A learner learning in a world, evaluated from time to time.

    Args:
        domain: the domain file.
        learner: a registered learner name.
        learner_params: its parameters.
        seed: seeds the agent and the learning interaction.
        world: the simulator world (:class:`~relrl.sim.world.World` or mapping; default the
            paper's).
        caregiver: the caregiver model's name.
        caregiver_params: overrides of its parameters while learning (e.g. placement weights
            that hold some places out).
        eval_steps: time units per evaluation run.
        eval_policy: ``behaviour`` (exploration kept, no learning) or ``greedy``.
        eval_caregiver_params: the caregiver's overrides while evaluating (default: the
            learning ones).
        timeout: seconds one gateway call (one control step) may run before the run stops
            with a QueryTimeout naming the rule.
    """

    def __init__(self, domain: str, learner: str, learner_params: Mapping[str, float],
                 seed: int, *, world: Any = None, caregiver: str = "paper",
                 caregiver_params: Mapping[str, Any] | None = None, eval_steps: int = 500,
                 eval_policy: str = "behaviour",
                 eval_caregiver_params: Mapping[str, Any] | None = None,
                 timeout: float = 60.0) -> None:
        from relrl.kb import KnowledgeBase, gateway_calls
        from relrl.learners import make_learner
        from relrl.loop import Agent, Interaction
        from relrl.sim.metrics import GazeMetrics
        from relrl.sim.sis import SharedAttentionEnv
        from relrl.sim.world import World

        self.t_start = time.perf_counter()
        self.calls0 = gateway_calls()
        self.world = World(**world) if isinstance(world, Mapping) else (world or World())
        self.caregiver = caregiver
        self.eval_steps = eval_steps
        self.explore = eval_policy == "behaviour"
        self.seed = seed
        self.eval_caregiver_params = dict(eval_caregiver_params if eval_caregiver_params
                                          is not None else caregiver_params or {})
        self.kb = KnowledgeBase(domain, timeout=timeout)
        try:
            self.learner = make_learner(learner, **dict(learner_params))
            self.agent = Agent(self.kb, self.learner, seed=seed)
            env = SharedAttentionEnv(caregiver, caregiver_params, world=self.world,
                                     max_steps=None, record_trace=False)
            self.metrics = GazeMetrics(env.caregiver.params.contact_hold)
            self.reward = 0.0
            self.learning = Interaction(env, self.agent, on_step=self._on_learning_step)
            self.learning.reset(seed=seed)
            self._eval_envs: dict[Any, Any] = {}
        except BaseException:
            self.kb.close()
            raise
        self.learning_states: set[int] = set()
        self.eval_states: set[int] = set()
        self.steps = 0
        self.learned = 0

    def _on_learning_step(self, record: Any) -> None:
        self.metrics.add(record.info["record"])
        self.reward += record.env_reward

    def learn(self, steps: int) -> None:
        """Continue learning for ``steps`` time units."""
        self.learning.run(steps, learning=True, keep=False)
        self.learning_states |= self.agent.states
        self.steps += steps
        self.learned += steps

    def evaluate(self, runs: int, *, which: tuple[int, int] | None = None,
                 sequence: Sequence[str] | None = None, world: Any = None,
                 by_place: bool = False) -> Any:
        """Evaluate without changing the learner: runs ``which`` of ``runs`` (all by default)
        by :func:`relrl.sim.evaluation.evaluate`, targets from ``sequence`` (default: the
        world's balanced sequence) in ``world`` (default: the learning world)."""
        from relrl.sim.evaluation import evaluate, evaluation_env

        world = world or self.world
        key = (tuple(sequence) if sequence is not None else None, world,
               repr(sorted(self.eval_caregiver_params.items())))
        env = self._eval_envs.get(key)
        if env is None:
            env = self._eval_envs[key] = evaluation_env(
                world=world, caregiver=self.caregiver,
                caregiver_params=self.eval_caregiver_params, steps=self.eval_steps,
                sequence=sequence)
        agent, explore = self.agent, self.explore
        before = set(agent.states)
        agent.states.clear()

        def on_run(k: int, run_seed: int) -> None:
            agent.reseed(run_seed)
            agent.end_episode()

        def policy(obs: Any, info: dict[str, Any]) -> Any:
            return agent.step(info["percepts"], learning=False, explore=explore).action

        try:
            with agent.preserved():
                result = evaluate(policy, runs=runs, steps=self.eval_steps, seed=self.seed,
                                  which=which, on_run=on_run, env=env, by_place=by_place)
        finally:
            self.eval_states.update(agent.states)
            agent.states = before
        self.steps += self.eval_steps * len(result.runs)
        return result

    def states_met(self) -> int | None:
        """Distinct state codes met while learning; None for a learner that reads the
        relational view only, for which the engine computes no code (every step reports
        0)."""
        return codes_met(self.learning_states)

    def memory(self) -> dict[str, int]:
        """The learner's memory in positions (and details)."""
        return dict(self.learner.size())

    def eye_contacts(self, first: int | None) -> dict[str, Any]:
        """Eye contacts established while learning, in the first ``first`` opportunities."""
        e = self.metrics.eye_contacts(first)
        return {"established": e.established, "opportunities": e.opportunities,
                "per_opportunity": [bool(f) for f in e.per_opportunity]}

    def learning_summary(self) -> dict[str, Any]:
        """What learning did so far: CGIs of the learning interaction, reward, events."""
        c, lit = self.metrics.cgi(), self.metrics.cgi_literal()
        return {"steps": self.learned, "cgi": _zero(c.value), "cgi_literal": _zero(lit.value),
                "mutual_gaze_events": self.metrics.mutual_gaze_events,
                "reward_per_step": self.reward / self.learned if self.learned else 0.0}

    def timing(self) -> dict[str, float]:
        """Wall-clock figures (kept out of results.json: they differ from run to run)."""
        from relrl.kb import gateway_calls

        elapsed = time.perf_counter() - self.t_start
        calls = gateway_calls() - self.calls0
        return {"seconds": elapsed, "steps": self.steps,
                "steps_per_second": self.steps / elapsed if elapsed else 0.0,
                "gateway_calls_per_step": calls / self.steps if self.steps else 0.0}

    def close(self) -> None:
        """Close the knowledge base; safe to call twice."""
        self.kb.close()

    def __enter__(self) -> Session:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def codes_met(codes: set[int]) -> int | None:
    """How many distinct state codes ``codes`` holds; None when they are only 0 (a learner
    that reads the relational view: the engine computes no code for it)."""
    return len(codes) if codes - {0} else None


def _zero(x: float) -> float:
    return 0.0 if math.isnan(x) else float(x)


def point_summary(evaluation: Any) -> dict[str, Any]:
    """The per-run figures of one evaluation, as stored in a job's curve."""
    return {"cgi_runs": evaluation.cgi, "cgi_literal_runs": evaluation.cgi_literal,
            "eye_contacts_runs": [int(r["eye_contacts"]) for r in evaluation.runs]}
