"""The evaluation protocol of Experiment 1, as one function for any policy.

The paper's protocol (section 5.1): learning stops; the robot is evaluated by ``runs`` (20)
runs of ``steps`` (500) time units without learning; the caregiver places the target by a
pre-established sequence (:func:`~relrl.sim.caregiver.evaluation_sequence`) and the
distractors at random; each run's CGI (Eq. 5) is computed, then their mean and standard
deviation. relrl's experiments and outside agents use the same function::

    from relrl.sim import evaluate
    result = evaluate(lambda obs, info: my_agent.act(obs), runs=20, steps=500, seed=0)
    result.cgi_mean, result.cgi_literal_mean, result.eye_contacts_mean

Choices: run *k* resets the simulator with its own seed (derived from ``seed``; the same on
every machine) and starts the target sequence at entry ``k * len(sequence) // runs``, so the
runs together cover the whole sequence even in large worlds. A run in which the robot never
shifts its gaze from the caregiver while she looks at a toy has no CGI (no shifts); it scores
0 (the robot followed no gaze), and the literal CGI likewise.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from relrl.sim.caregiver import make_caregiver
from relrl.sim.errors import SimError
from relrl.sim.sis import SharedAttentionEnv
from relrl.sim.world import World

__all__ = ["Evaluation", "evaluate", "evaluation_env", "evaluation_seeds"]

#: a policy: ``(observation, info) -> action`` (an index, a ``look(P)`` term or its text).
Policy = Callable[[Any, dict[str, Any]], Any]


def evaluation_seeds(seed: int, runs: int) -> list[int]:
    """The reset seed of each evaluation run, derived from ``seed`` (machine-independent)."""
    return [int(s) for s in np.random.SeedSequence([int(seed), 1]).generate_state(runs)]


@dataclass
class Evaluation:
    """The result of :func:`evaluate`.

    Attributes:
        runs: one metrics dict per run (:meth:`relrl.sim.metrics.GazeMetrics.summary`, with
            CGIs of runs without shifts set to 0 and ``run`` / ``seed`` added).
    """

    runs: list[dict[str, Any]] = field(default_factory=list)

    def _values(self, key: str) -> list[float]:
        return [float(r[key]) for r in self.runs]

    @property
    def cgi(self) -> list[float]:
        """relrl's CGI of each run."""
        return self._values("cgi")

    @property
    def cgi_literal(self) -> list[float]:
        """The literal CGI (Eq. 5 as written) of each run."""
        return self._values("cgi_literal")

    @property
    def cgi_mean(self) -> float:
        """Mean CGI over the runs (NaN without runs)."""
        return float(np.mean(self.cgi)) if self.runs else math.nan

    @property
    def cgi_std(self) -> float:
        """Standard deviation of the CGI over the runs."""
        return float(np.std(self.cgi)) if self.runs else math.nan

    @property
    def cgi_literal_mean(self) -> float:
        """Mean literal CGI over the runs."""
        return float(np.mean(self.cgi_literal)) if self.runs else math.nan

    @property
    def eye_contacts_mean(self) -> float:
        """Mean number of eye contacts established per run."""
        return float(np.mean(self._values("eye_contacts"))) if self.runs else math.nan

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form: the runs and the means."""
        return {"runs": [dict(r) for r in self.runs], "cgi_mean": self.cgi_mean,
                "cgi_std": self.cgi_std, "cgi_literal_mean": self.cgi_literal_mean,
                "eye_contacts_mean": self.eye_contacts_mean}


def evaluate(policy: Policy, *, world: World | Mapping[str, Any] | None = None,
             caregiver: str = "paper",
             caregiver_params: Mapping[str, Any] | None = None, runs: int = 20,
             steps: int = 500, seed: int = 0, sequence: Sequence[str] | None = None,
             which: tuple[int, int] | None = None,
             on_run: Callable[[int, int], None] | None = None,
             env: SharedAttentionEnv | None = None, observation: int = 0,
             by_place: bool = False) -> Evaluation:
    """Evaluate a policy by the paper's protocol.

    Args:
        policy: ``(observation, info) -> action``; it must not learn (evaluation measures).
        world: a :class:`~relrl.sim.world.World` or a mapping of its fields (default: the
            paper's world).
        caregiver: the caregiver model's name.
        caregiver_params: overrides of its parameters (reliability, latency, ...).
        runs: evaluation runs.
        steps: time units per run.
        seed: derives every run's seed (:func:`evaluation_seeds`).
        sequence: the target places in order (default: the world's balanced sequence).
            Zero-shot transfer passes the held-out places here.
        which: ``(start, stop)``: compute only these runs (to split one evaluation over
            processes; the parts concatenate to the whole).
        on_run: called as ``on_run(k, run_seed)`` before run *k* starts (e.g. to reseed an
            agent's random streams and clear its working memory).
        env: an evaluation environment built by :func:`evaluation_env` (saves building one).
        observation: the observation version the policy reads (0: ``-v0``, 1: ``-v1``).
        by_place: add each run's ``by_place``: per place the caregiver looked at,
            ``[correct shifts, shifts]``.

    Returns:
        An :class:`Evaluation` with one metrics dict per run.
    """
    if not isinstance(runs, int) or runs < 1 or not isinstance(steps, int) or steps < 1:
        raise SimError(f"runs={runs!r}, steps={steps!r}: use whole numbers >= 1")
    if env is None:
        env = evaluation_env(world=world, caregiver=caregiver,
                             caregiver_params=caregiver_params, steps=steps, sequence=sequence,
                             observation=observation)
    seq_len = len(env.caregiver.params.target_sequence)
    seeds = evaluation_seeds(seed, runs)
    start, stop = which if which is not None else (0, runs)
    result = Evaluation()
    for k in range(start, stop):
        if on_run is not None:
            on_run(k, seeds[k])
        obs, info = env.reset(seed=seeds[k], options={"sequence_offset": k * seq_len // runs})
        for _ in range(steps):
            obs, _, _, _, info = env.step(policy(obs, info))
        metrics = env.metrics()
        if by_place:
            metrics["by_place"] = {p: list(c) for p, c in
                                   sorted(env.gaze_metrics.by_place.items())}
        for key in ("cgi", "cgi_literal"):
            if math.isnan(metrics[key]):
                metrics[key] = 0.0
        result.runs.append({"run": k, "seed": seeds[k], **metrics})
    return result


def evaluation_env(*, world: World | Mapping[str, Any] | None = None,
                   caregiver: str = "paper", caregiver_params: Mapping[str, Any] | None = None,
                   steps: int = 500, sequence: Sequence[str] | None = None,
                   observation: int = 0) -> SharedAttentionEnv:
    """The simulator in evaluation mode: targets from ``sequence`` (default: the world's
    balanced sequence), ``steps`` time units per episode, no stored trace."""
    if isinstance(world, Mapping):
        world = World(**world)
    world = world or World()
    params = world.caregiver_params(caregiver_params, caregiver)
    params = params.for_evaluation(tuple(sequence) if sequence is not None else None)
    return SharedAttentionEnv(make_caregiver(caregiver, params), world=world,
                              observation=observation, max_steps=steps, record_trace=False)
