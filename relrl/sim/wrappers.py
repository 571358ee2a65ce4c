"""Gymnasium wrappers for outside agents.

:class:`RelationalObservation` replaces the observation vector by the *relational view* of the
time unit: the ground facts a relational learner reads, as a sorted tuple of Prolog text, e.g.
``("gaze(face,left)", "head_at(centre)", "sees(face)")``. The tuple is hashable, so a tabular
agent can key a table on it; a first-order agent can parse it.

The view is the world's domain's (:class:`RelationalView`): the world's generated domain
(:mod:`relrl.sim.domain`) is loaded into a knowledge base, each time unit's percepts go into
its working memory, and the facts are the ground solutions of its ``relation/1`` templates
(docs/tg.md) -- what the tg learner reads, from the one definition of it. For the paper's
world: ``see(X)`` gives ``sees(X)``, ``pose(face, P)`` ``gaze(face,P)`` (``centre`` for
``frontal``: the caregiver looks at the robot), ``at(P)`` ``head_at(P)``, ``at(toy, P)``
``toy_at(toy,P)``, ``colour(toy, C)`` ``colour(toy,C)``, ``hear(W)`` ``heard(W)``; whole-scene
worlds see each toy in view as ``toy(P)``.
"""

from __future__ import annotations

import string
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
from gymnasium import spaces

from relrl.engine import one
from relrl.kb import KnowledgeBase
from relrl.sim.world import World
from relrl.terms import Term, format_term

__all__ = ["EpisodeScalars", "RelationalObservation", "RelationalView"]

#: what ``info`` holds at an episode's end that :class:`EpisodeScalars` writes.
EPISODE_METRICS = ("cgi", "cgi_literal", "eye_contacts", "opportunities", "shifts",
                   "mutual_gaze_events")

_CHARSET = string.ascii_lowercase + string.digits + "_(),"


class RelationalView:
    """The relational view of a world's time units, from its domain's ``relation/1``.

    Holds a knowledge base of the world's domain until :meth:`close` (also a context
    manager).

    Example:
        >>> with RelationalView(World()) as view:
        ...     view([("see", "face"), ("pose", "face", "frontal"), ("at", "centre")])
        ('gaze(face,centre)', 'head_at(centre)', 'sees(face)')
    """

    def __init__(self, world: World) -> None:
        with tempfile.TemporaryDirectory(prefix="relrl-view-") as folder:
            self.kb = KnowledgeBase(world.write_domain(folder))

    def __call__(self, percepts: Sequence[Term]) -> tuple[str, ...]:
        """The relational view of one time unit's percepts, sorted (their text)."""
        self.kb.insert(percepts)
        return tuple(sorted(format_term(f)
                            for f in one(self.kb, "relational_state", self.kb.module)))

    def close(self) -> None:
        """Drop the knowledge base. Safe to call twice."""
        self.kb.close()

    def __enter__(self) -> RelationalView:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class RelationalObservation(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    """Observations are the relational facts of the time unit (a sorted tuple of text).

    ``info["relational"]`` holds the same tuple. Works on ``relrl/SharedAttention-v0`` and
    ``-v1`` (any world).

    Example:
        >>> env = RelationalObservation(gym.make("relrl/SharedAttention-v1",
        ...                                      world={"places": 9}))       # doctest: +SKIP
        >>> obs, info = env.reset(seed=0)                                    # doctest: +SKIP
        >>> obs                                                              # doctest: +SKIP
        ('gaze(face,centre)', 'head_at(left_2)', ...)
    """

    def __init__(self, env: gym.Env) -> None:
        gym.utils.RecordConstructorArgs.__init__(self)
        gym.ObservationWrapper.__init__(self, env)
        self.view = RelationalView(env.unwrapped.world)
        self.observation_space = spaces.Sequence(spaces.Text(max_length=64, charset=_CHARSET))
        self._last: tuple[str, ...] = ()

    def reset(self, **kwargs: Any) -> tuple[tuple[str, ...], dict[str, Any]]:
        """Reset the wrapped environment; the observation is the relational view."""
        obs, info = self.env.reset(**kwargs)
        self._last = self.view(info["percepts"])
        info["relational"] = self._last
        return self._last, info

    def step(self, action: Any) -> tuple[tuple[str, ...], float, bool, bool, dict[str, Any]]:
        """Step the wrapped environment; the observation is the relational view."""
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._last = self.view(info["percepts"])
        info["relational"] = self._last
        return self._last, reward, terminated, truncated, info

    def observation(self, observation: Any) -> tuple[str, ...]:
        """The relational view of the last time unit (computed from its percepts)."""
        return self._last

    def close(self) -> None:
        """Close the wrapped environment and drop the view's knowledge base."""
        self.view.close()
        super().close()


class EpisodeScalars(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Every finished episode as TensorBoard scalars in ``folder`` (``tensorboard --logdir``
    reads it while the agent trains): ``episode/return``, ``episode/length`` and the gaze
    metrics ``info`` holds at the episode's end (``episode/cgi``, ``episode/eye_contacts``,
    ...), at the number of steps taken so far (the x axis of Stable-Baselines3's logs).
    :attr:`episodes` keeps the same numbers for the program.

    Example:
        >>> env = EpisodeScalars(gym.make("relrl/SharedAttention-v1"), "runs/ppo")
        ... # doctest: +SKIP
        >>> model = PPO("MlpPolicy", env).learn(50_000)                      # doctest: +SKIP

    Args:
        env: the environment (``relrl/SharedAttention-v0`` or ``-v1``: any world).
        folder: where the event file goes (created when missing).
    """

    def __init__(self, env: gym.Env, folder: str | Path) -> None:
        from relrl.tensorboard import EVENT_FILE, ScalarLog

        gym.utils.RecordConstructorArgs.__init__(self, folder=str(folder))
        gym.Wrapper.__init__(self, env)
        self.log = ScalarLog(Path(folder) / EVENT_FILE)
        self.episodes: list[dict[str, float]] = []
        self.steps = 0
        self._return = 0.0
        self._length = 0

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        """Reset the wrapped environment; a new episode starts."""
        self._return, self._length = 0.0, 0
        return self.env.reset(**kwargs)

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Step the wrapped environment; at an episode's end, write its scalars."""
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.steps += 1
        self._return += float(reward)
        self._length += 1
        if terminated or truncated:
            episode = {"return": self._return, "length": float(self._length),
                       **{k: info[k] for k in EPISODE_METRICS if k in info}}
            self.episodes.append(episode)
            self.log.add(self.steps, {f"episode/{k}": v for k, v in episode.items()})
            self._return, self._length = 0.0, 0
        return obs, reward, terminated, truncated, info

    def close(self) -> None:
        """Write what is left and close the event file and the environment."""
        self.log.close()
        super().close()
