"""The Social Interactive Simulator (SIS) as a Gymnasium environment.

A robot and a caregiver face to face, 50 cm apart, with up to five toy places between them
(da Silva & Romero 2012, section 5.1, after Triesch et al. 2006). One step is one time unit:
the robot's response (``look(P)``) turns its head to place P, the caregiver (a model from
:mod:`relrl.sim.caregiver`) reacts, and the robot perceives what is at its new focus.

Percepts (``info["percepts"]``, the vocabulary of ``examples/domains/sis.pl``):

* on the caregiver (``centre``): ``see(face)``, ``pose(face, G)`` with G where the caregiver
  looks — ``frontal`` (at the robot), ``left``, ``left_down``, ``down``, ``right_down``,
  ``right``;
* on a toy: ``see(toy)``, ``at(toy, P)`` and ``colour(toy, C)`` (if toys have colours);
* on an empty place: ``see(environment)``;
* always ``at(P)``: where the robot's head points; and ``hear(attention)`` in the time unit
  the caregiver gives attention (the reinforcer).

Observation (``MultiDiscrete``; see :data:`OBSERVATION_FIELDS`): the same information as
integers, ``[head_at, seen, pose, colour, attention]`` (a new ``int64`` array each call).

Action: ``Discrete(6)``, action ``i`` is ``look(PLACES[i])`` (:data:`RESPONSES`). ``step``
also takes the response term ``("look", "left")`` or its text ``"look(left)"``.

Reward: ``reward_attention`` (+10) in a time unit with ``hear(attention)``, else
``reward_other`` (-1), the paper's values. Episodes never terminate; they are truncated after
``max_steps`` time units (``None``: never; stepping on after truncation is allowed).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from perception.vocabulary import SIS_POSES
from relrl.interfaces import Environment
from relrl.sim.caregiver import Caregiver, CaregiverParams, make_caregiver
from relrl.sim.errors import InvalidResponse, SimError, did_you_mean
from relrl.sim.metrics import StepRecord
from relrl.sim.places import ANGLE_BETWEEN, CENTRE, PLACES, place_index
from relrl.sim.render import render_rgb, render_text

__all__ = ["ENV_ID", "OBSERVATION_FIELDS", "POSES", "RESPONSES", "SharedAttentionEnv"]

#: the registered Gymnasium id.
ENV_ID = "relrl/SharedAttention-v0"
#: action index -> response term.
RESPONSES: tuple[tuple[str, str], ...] = tuple(("look", p) for p in PLACES)
#: caregiver gaze (place index) -> the face's pose as the robot perceives it (the SIS world's
#: vocabulary: the place looked at, ``frontal`` for the robot).
POSES: tuple[str, ...] = SIS_POSES
#: the observation vector, field by field.
OBSERVATION_FIELDS: tuple[tuple[str, str], ...] = (
    ("head_at", "where the robot's head points: index into PLACES (0 = centre)"),
    ("seen", "0 = nothing (see(environment)), 1 = the face, 2 = a toy"),
    ("pose", "0 = no face in view, else 1 + index into POSES (1 = frontal, 2 = left, ...)"),
    ("colour", "0 = no coloured toy in view, else 1 + index into the caregiver's toy_colours"),
    ("attention", "1 in a time unit with hear(attention), else 0"),
)

_ACTIONS: dict[Any, int] = {}
for _i, _term in enumerate(RESPONSES):
    _ACTIONS[_i] = _i
    _ACTIONS[_term] = _i
    _ACTIONS[f"look({_term[1]})"] = _i

_SEE_FACE, _SEE_TOY, _SEE_ENV = ("see", "face"), ("see", "toy"), ("see", "environment")
_HEAR = ("hear", "attention")


class SharedAttentionEnv(gym.Env, Environment):
    """The SIS: a Gymnasium environment and a :class:`relrl.interfaces.Environment`.

    Args:
        caregiver: a registered caregiver name (``paper``, ``unreliable``, ``random``,
            ``one_toy``; see :func:`relrl.sim.caregiver.caregiver_names`) or a built
            :class:`~relrl.sim.caregiver.Caregiver`.
        caregiver_params: full :class:`~relrl.sim.caregiver.CaregiverParams`, or a mapping of
            overrides of the named preset (e.g. ``{"reliability": 0.7}``).
        render_mode: ``None``, ``"ansi"`` (text) or ``"rgb_array"`` (a top view).
        max_steps: time units per episode before truncation (``None``: never truncate).
        reward_attention: reward in a time unit with ``hear(attention)``.
        reward_other: reward in any other time unit.
        initial_focus: where the robot looks after ``reset`` (a place name); ``None`` draws
            it from the seeded generator. ``reset(options={"focus": P})`` overrides it.
        record_trace: keep :attr:`trace` (one :class:`StepRecord` per time unit).

    Attributes:
        caregiver: the caregiver model.
        trace: the records of the current episode (a new list at each ``reset``).
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["ansi", "rgb_array"], "render_fps": 4}

    def __init__(self, caregiver: str | Caregiver = "paper",
                 caregiver_params: CaregiverParams | Mapping[str, Any] | None = None, *,
                 render_mode: str | None = None, max_steps: int | None = 500,
                 reward_attention: float = 10.0, reward_other: float = -1.0,
                 initial_focus: str | None = None, record_trace: bool = True) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise SimError(f"render_mode={render_mode!r}: use None, "
                           + " or ".join(repr(m) for m in self.metadata["render_modes"]))
        if max_steps is not None and (not isinstance(max_steps, int) or max_steps < 1):
            raise SimError(f"max_steps={max_steps!r}: use a whole number >= 1 or None")
        if isinstance(caregiver, Caregiver):
            if caregiver_params is not None:
                raise SimError("caregiver_params only applies to a caregiver given by name")
            self.caregiver = caregiver
        else:
            self.caregiver = make_caregiver(caregiver, caregiver_params)
        self.initial_focus = self._place(initial_focus)
        self.render_mode = render_mode
        self.max_steps = max_steps
        self.reward_attention = float(reward_attention)
        self.reward_other = float(reward_other)
        self.record_trace = record_trace
        colours = self.caregiver.params.toy_colours
        self._colour_code = {c: i + 1 for i, c in enumerate(colours)}
        self._colour_code[""] = 0
        self.action_space = spaces.Discrete(len(PLACES))
        self.observation_space = spaces.MultiDiscrete(
            [len(PLACES), 3, len(POSES) + 1, len(colours) + 1, 2])
        self._cache: dict[tuple, tuple[np.ndarray, tuple]] = {}
        self.trace: list[StepRecord] = []
        self._t = 0
        self._focus = CENTRE
        self._record: StepRecord | None = None
        self._closed = False

    # ---- the Gymnasium API -----------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an interaction: the caregiver looks at the robot, no toys out.

        Args:
            seed: seeds the generator (same seed, same interaction for the same actions).
            options: ``{"focus": place}`` sets where the robot looks first.

        Returns:
            The first observation and ``info`` (``percepts``, ``record``, ``toy_angles``).
        """
        super().reset(seed=seed)
        focus = self._place((options or {}).get("focus")) if options else None
        if focus is None:
            focus = self.initial_focus
        if focus is None:
            focus = int(self.np_random.integers(len(PLACES)))
        self._t = 0
        self._focus = focus
        self.caregiver.reset(self.np_random, focus)
        self.trace = []
        obs, info = self._observe()
        return obs, info

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Emit a response (action index or ``look(P)`` term) and advance one time unit.

        Returns:
            ``(observation, reward, terminated, truncated, info)``; ``terminated`` is always
            False; ``info`` holds ``percepts``, ``record`` and ``toy_angles``.
        """
        try:
            focus = _ACTIONS[action]
        except (KeyError, TypeError):
            raise InvalidResponse(
                f"not a response of the SIS: {action!r}"
                f"{did_you_mean(str(action), [f'look({p})' for p in PLACES])}; use an action "
                f"index 0-5 or one of " + ", ".join(f"look({p})" for p in PLACES)) from None
        if self._record is None:
            raise SimError("call reset() before step()")
        self._t += 1
        self._focus = focus
        self.caregiver.update(focus)
        obs, info = self._observe()
        reward = self.reward_attention if self.caregiver.attention else self.reward_other
        truncated = self.max_steps is not None and self._t >= self.max_steps
        return obs, reward, False, truncated, info

    def render(self) -> str | np.ndarray | None:
        """Draw the current time unit in the ``render_mode`` given at construction."""
        if self._record is None:
            raise SimError("call reset() before render()")
        if self.render_mode == "ansi":
            return render_text(self._record)
        if self.render_mode == "rgb_array":
            return render_rgb(self._record)
        gym.logger.warn("render() called with render_mode=None; pass render_mode='ansi' or "
                        "'rgb_array' when making the environment")
        return None

    def close(self) -> None:
        """Release nothing (no resources are held); safe to call twice."""
        self._closed = True

    # ---- extras ----------------------------------------------------------------------------

    @property
    def time(self) -> int:
        """The current time unit (0 after ``reset``)."""
        return self._t

    @property
    def focus(self) -> str:
        """Where the robot's head points now."""
        return PLACES[self._focus]

    @property
    def record(self) -> StepRecord | None:
        """The record of the current time unit (``None`` before ``reset``)."""
        return self._record

    def toy_angles(self) -> tuple[tuple[str, float], ...]:
        """For each toy out, ``(place, degrees)`` the robot's head must turn to focus it."""
        row = ANGLE_BETWEEN[self._focus]
        return tuple((place, row[place_index(place)]) for place, _ in self.caregiver.toys)

    # ---- internals -------------------------------------------------------------------------

    @staticmethod
    def _place(name: str | None) -> int | None:
        if name is None:
            return None
        try:
            return place_index(name)
        except (KeyError, TypeError):
            raise SimError(f"unknown place {name!r}{did_you_mean(str(name), PLACES)}; use one "
                           f"of {', '.join(PLACES)}") from None

    def _observe(self) -> tuple[np.ndarray, dict[str, Any]]:
        cg = self.caregiver
        focus, attention = self._focus, cg.attention
        key = (focus, cg.gaze if focus == CENTRE else cg.toy_at[focus], attention)
        cached = self._cache.get(key)
        if cached is None:
            cached = self._cache[key] = self._encode(*key)
        obs, percepts = cached
        obs = obs.copy()  # users keep observations: never hand out the same array twice
        target = cg.target
        rec = StepRecord(self._t, PLACES[focus], POSES[cg.gaze], cg.phase, cg.opportunity,
                         cg.trial, cg.toys, PLACES[target] if target >= 0 else None,
                         attention, cg.contact)
        self._record = rec
        if self.record_trace:
            self.trace.append(rec)
        info = {"percepts": list(percepts), "record": rec,
                "toy_angles": self.toy_angles() if cg.toys else ()}
        return obs, info

    def _encode(self, focus: int, what: Any, attention: bool) -> tuple[np.ndarray, tuple]:
        """Observation and percepts of one (focus, thing in view, attention) combination."""
        place = PLACES[focus]
        if focus == CENTRE:
            percepts = [_SEE_FACE, ("pose", "face", POSES[what])]
            seen, pose, colour = 1, 1 + what, 0
        elif what is None:
            percepts = [_SEE_ENV]
            seen, pose, colour = 0, 0, 0
        else:
            percepts = [_SEE_TOY, ("at", "toy", place)]
            if what:
                percepts.append(("colour", "toy", what))
            seen, pose, colour = 2, 0, self._colour_code[what]
        percepts.append(("at", place))
        if attention:
            percepts.append(_HEAR)
        obs = np.array([focus, seen, pose, colour, int(attention)], dtype=np.int64)
        return obs, tuple(percepts)
