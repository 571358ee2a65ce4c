"""Scripted robot policies for the simulator: baselines, checks and demos.

A policy maps the percepts of a time unit (``info["percepts"]``) to a response term. Two are
given: :class:`GazeFollower` (the ideal learner's end point: look at the caregiver, then where
the caregiver looks) and :class:`RandomPolicy` (a uniformly random look, the floor of the CGI
at 1/5). :func:`rollout` runs one on an environment; :func:`bench_step_rate` measures how fast
the simulator steps.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import numpy as np

from relrl.sim.metrics import StepRecord
from relrl.sim.places import PLACES
from relrl.terms import Term

__all__ = ["GazeFollower", "Policy", "RandomPolicy", "bench_step_rate", "rollout"]

#: a policy: the percepts of a time unit -> a response term.
Policy = Callable[[Sequence[Term]], Term]

_CENTRE = ("look", "centre")


class GazeFollower:
    """Look at the caregiver; when its face turns to a place, look there; then come back.

    Sees the face frontal -> ``look(centre)``; sees ``pose(face, P)`` -> ``look(P)``;
    sees anything else -> ``look(centre)``.
    """

    def __call__(self, percepts: Sequence[Term]) -> Term:
        """Choose the response for these percepts."""
        for p in percepts:
            if p[0] == "pose" and p[2] != "frontal":
                return ("look", p[2])
        return _CENTRE


class RandomPolicy:
    """Look at one of the places uniformly at random (seeded).

    Args:
        seed: seeds the policy's own generator.
        places: every place of the world, ``centre`` included (default: the paper's six).
    """

    def __init__(self, seed: int | None = None, places: Sequence[str] = PLACES) -> None:
        self._rng = np.random.default_rng(seed)
        self._looks = [("look", p) for p in places]

    def __call__(self, percepts: Sequence[Term]) -> Term:
        """Choose a response, ignoring the percepts."""
        return self._looks[int(self._rng.integers(len(self._looks)))]


def rollout(env, policy: Policy, steps: int, seed: int | None = None) -> list[StepRecord]:
    """Reset ``env`` with ``seed`` and run ``policy`` for ``steps`` time units.

    The environment should be built with ``max_steps=None`` (or at least ``steps``) and
    ``record_trace=True``. Returns the trace (``steps + 1`` records, reset's first).
    """
    _, info = env.reset(seed=seed)
    for _ in range(steps):
        _, _, _, _, info = env.step(policy(info["percepts"]))
    return env.trace


def bench_step_rate(steps: int = 200_000, seed: int = 0, record_trace: bool = True
                    ) -> dict[str, float]:
    """Time ``step()`` alone on random action indices.

    Returns:
        ``{"steps": n, "seconds": s, "steps_per_second": n / s}``.
    """
    from relrl.sim.sis import SharedAttentionEnv

    env = SharedAttentionEnv(max_steps=None, record_trace=record_trace)
    env.reset(seed=seed)
    actions = np.random.default_rng(seed).integers(len(PLACES), size=steps).tolist()
    step = env.step
    start = time.perf_counter()
    for a in actions:
        step(a)
    seconds = time.perf_counter() - start
    env.close()
    return {"steps": steps, "seconds": seconds, "steps_per_second": steps / seconds}
