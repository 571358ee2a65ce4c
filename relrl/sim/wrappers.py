"""Gymnasium wrappers for outside agents.

:class:`EpisodeScalars` writes every finished episode's return, length and gaze metrics (the
CGI and the rest that ``info`` holds at truncation) as TensorBoard scalars, whatever agent
library steps the environment (Stable-Baselines3, a loop of your own).

:class:`RelationalObservation` replaces the observation vector by the *relational view* of the
time unit: the ground facts a relational learner reads (the ``relation/1`` templates of the
generated domains and ``examples/domains/sis.pl``; docs/tg.md), as a sorted tuple of Prolog
text, e.g. ``("gaze(face,left)", "head_at(centre)", "sees(face)")``. The tuple is hashable,
so a tabular agent can key a table on it; a first-order agent can parse it.

============================  ==========================================================
percept of the time unit      relational fact
============================  ==========================================================
``see(X)``                    ``sees(X)``
``pose(face, frontal)``       ``gaze(face,centre)`` (the caregiver looks at the robot)
``pose(face, P)``             ``gaze(face,P)``
``at(P)``                     ``head_at(P)``
``at(toy, P)``                ``toy_at(toy,P)`` (focus-only worlds)
``colour(toy, C)``            ``colour(toy,C)`` (focus-only worlds)
``kind(toy, K)``              ``kind(toy,K)`` (focus-only worlds)
``in_view(P, C, K)``          ``toy_at(toy(P),P)``, ``colour(toy(P),C)``, ``kind(toy(P),K)``
                              (whole-scene worlds; ``none`` values give no fact)
``hear(W)``                   ``heard(W)``
============================  ==========================================================

A test holds this table to the Prolog definitions of the generated domains.
"""

from __future__ import annotations

import string
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
from gymnasium import spaces

from relrl.terms import Term

__all__ = ["EpisodeScalars", "RelationalObservation", "relational_facts"]

#: what ``info`` holds at an episode's end that :class:`EpisodeScalars` writes.
EPISODE_METRICS = ("cgi", "cgi_literal", "eye_contacts", "opportunities", "shifts",
                   "mutual_gaze_events")

_CHARSET = string.ascii_lowercase + string.digits + "_(),"


def relational_facts(percepts: Sequence[Term], scene: bool = False) -> tuple[str, ...]:
    """The relational view of one time unit's percepts, sorted (see the module table)."""
    facts: set[str] = set()
    add = facts.add
    for p in percepts:
        head = p[0]
        if head == "see":
            add(f"sees({p[1]})")
        elif head == "pose":
            add(f"gaze({p[1]},{'centre' if p[2] == 'frontal' else p[2]})")
        elif head == "at":
            if len(p) == 2:
                add(f"head_at({p[1]})")
            elif not scene:
                add(f"toy_at({p[1]},{p[2]})")
        elif head in ("colour", "kind") and not scene:
            add(f"{head}({p[1]},{p[2]})")
        elif head == "in_view":
            place, colour, kind = p[1], p[2], p[3]
            add(f"toy_at(toy({place}),{place})")
            if colour != "none":
                add(f"colour(toy({place}),{colour})")
            if kind != "none":
                add(f"kind(toy({place}),{kind})")
        elif head == "hear":
            add(f"heard({p[1]})")
    return tuple(sorted(facts))


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
        self._scene = bool(getattr(env.unwrapped, "world", None) and env.unwrapped.world.scene)
        self.observation_space = spaces.Sequence(spaces.Text(max_length=64, charset=_CHARSET))
        self._last: tuple[str, ...] = ()

    def reset(self, **kwargs: Any) -> tuple[tuple[str, ...], dict[str, Any]]:
        """Reset the wrapped environment; the observation is the relational view."""
        obs, info = self.env.reset(**kwargs)
        self._last = relational_facts(info["percepts"], self._scene)
        info["relational"] = self._last
        return self._last, info

    def step(self, action: Any) -> tuple[tuple[str, ...], float, bool, bool, dict[str, Any]]:
        """Step the wrapped environment; the observation is the relational view."""
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._last = relational_facts(info["percepts"], self._scene)
        info["relational"] = self._last
        return self._last, reward, terminated, truncated, info

    def observation(self, observation: Any) -> tuple[str, ...]:
        """The relational view of the last time unit (computed from its percepts)."""
        return self._last


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
