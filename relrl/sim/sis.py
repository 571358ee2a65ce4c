"""The Social Interactive Simulator (SIS) as a Gymnasium environment.

A robot and a caregiver face to face, 50 cm apart, with toy places between them (da Silva &
Romero 2012, section 5.1, after Triesch et al. 2006; five places in the paper's world, more in
a :class:`~relrl.sim.world.World` that grows). One step is one time unit: the robot's response
(``look(P)``) turns its head to place P, the caregiver (a model from
:mod:`relrl.sim.caregiver`) reacts, and the robot perceives what is at its new focus.

Percepts (``info["percepts"]``, the vocabulary of ``examples/domains/sis.pl`` and of the
generated world domains):

* on the caregiver (``centre``): ``see(face)``, ``pose(face, G)`` with G where the caregiver
  looks — ``frontal`` (at the robot) or a toy place;
* on a toy: ``see(toy)``, ``at(toy, P)``, ``colour(toy, C)`` (if toys have colours) and
  ``kind(toy, K)`` (if toys have kinds);
* on an empty place: ``see(environment)``;
* with whole-scene perception (``World(scene=True)``), for every toy in the field of view:
  ``in_view(P, C, K)`` (``C``/``K`` are ``none`` when toys have no colour/kind);
* always ``at(P)``: where the robot's head points; and ``hear(attention)`` in the time unit
  the caregiver gives attention (the reinforcer).

Observation (``MultiDiscrete``; see :func:`observation_fields`): the focus as integers,
``[head_at, seen, pose, colour, attention]`` (``relrl/SharedAttention-v0``); the successor
``relrl/SharedAttention-v1`` adds ``kind`` and, with whole-scene perception, one field per toy
place (what is in view there).

Action: ``Discrete(P + 1)``, action ``i`` is ``look(places[i])`` (``RESPONSES`` for the
paper's world). ``step`` also takes the response term ``("look", "left")`` or its text
``"look(left)"``.

Reward: :mod:`relrl.reward` (+10 in a time unit with ``hear(attention)``, else -1).
Episodes never terminate; they are truncated after ``max_steps`` time units (``None``:
never; stepping on after truncation is allowed). At truncation ``info`` also holds the
episode's metrics: ``cgi``, ``cgi_literal``, ``eye_contacts``, ``opportunities``, ``shifts``,
``all_shifts``, ``mutual_gaze_events`` (:meth:`SharedAttentionEnv.metrics` gives them at any
time).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from perception.vocabulary import SIS_POSES
from relrl.interfaces import Environment
from relrl.reward import PAPER_REWARD
from relrl.sim.caregiver import Caregiver, CaregiverParams, make_caregiver
from relrl.sim.errors import InvalidResponse, SimError, did_you_mean
from relrl.sim.metrics import GazeMetrics, StepRecord
from relrl.sim.places import CENTRE, PLACES, layout
from relrl.sim.render import render_rgb, render_text
from relrl.sim.world import World

__all__ = ["ENV_ID", "ENV_ID_V1", "OBSERVATION_FIELDS", "POSES", "RESET_OPTIONS", "RESPONSES",
           "SharedAttentionEnv", "SharedAttentionEnvV1", "observation_fields"]

#: the registered Gymnasium id (focus-only observation).
ENV_ID = "relrl/SharedAttention-v0"
#: the successor: the observation adds the toy's kind and the whole scene.
ENV_ID_V1 = "relrl/SharedAttention-v1"
#: the options ``reset(options=...)`` takes (any other is refused, with a suggestion).
RESET_OPTIONS: tuple[str, ...] = ("focus", "sequence_offset")
#: action index -> response term (the paper's world).
RESPONSES: tuple[tuple[str, str], ...] = tuple(("look", p) for p in PLACES)
#: caregiver gaze (place index) -> the face's pose as the robot perceives it in the paper's
#: world (the shared vocabulary: the place looked at, ``frontal`` for the robot).
POSES: tuple[str, ...] = SIS_POSES
#: the v0 observation vector, field by field.
OBSERVATION_FIELDS: tuple[tuple[str, str], ...] = (
    ("head_at", "where the robot's head points: index into the places (0 = centre)"),
    ("seen", "0 = nothing (see(environment)), 1 = the face, 2 = a toy"),
    ("pose", "0 = no face in view, else 1 + index into the poses (1 = frontal, 2 = the "
             "first toy place, ...)"),
    ("colour", "0 = no coloured toy in view, else 1 + index into the caregiver's toy_colours"),
    ("attention", "1 in a time unit with hear(attention), else 0"),
)
_KIND_FIELD = ("kind", "0 = no toy with a kind in view, else 1 + index into toy_kinds")

_SEE_FACE, _SEE_TOY, _SEE_ENV = ("see", "face"), ("see", "toy"), ("see", "environment")
_HEAR = ("hear", "attention")


def observation_fields(version: int = 0, places: tuple[str, ...] = (),
                       scene: bool = False) -> tuple[tuple[str, str], ...]:
    """The fields of an observation vector: ``(name, meaning)`` in order.

    Version 0 is :data:`OBSERVATION_FIELDS`; version 1 adds ``kind`` and, with whole-scene
    perception, ``scene_P`` for each toy place P: 0 = no toy in view there, else
    ``1 + colour_index * max(1, K) + kind_index``.
    """
    if version == 0:
        return OBSERVATION_FIELDS
    fields = OBSERVATION_FIELDS[:4] + (_KIND_FIELD,) + OBSERVATION_FIELDS[4:]
    if scene:
        fields += tuple((f"scene_{p}", f"the toy in view at {p}: 0 = none, else 1 + "
                         "colour_index * max(1, K) + kind_index") for p in places)
    return fields


class SharedAttentionEnv(gym.Env, Environment):
    """The SIS: a Gymnasium environment and a :class:`relrl.interfaces.Environment`.

    Args:
        caregiver: a registered caregiver name (``paper``, ``unreliable``, ``random``,
            ``one_toy``; see :func:`relrl.sim.caregiver.caregiver_names`) or a built
            :class:`~relrl.sim.caregiver.Caregiver`.
        caregiver_params: full :class:`~relrl.sim.caregiver.CaregiverParams`, or a mapping of
            overrides of the named preset (e.g. ``{"reliability": 0.7}``).
        world: a :class:`~relrl.sim.world.World` (or a mapping of its fields, e.g.
            ``{"places": 9, "scene": True}``): the caregiver's places, colours, kinds and toys
            and the robot's perception. ``None``: the paper's world, or the places of a
            caregiver given built or with full parameters.
        observation: observation version, 0 (``relrl/SharedAttention-v0``) or 1 (``-v1``).
        render_mode: ``None``, ``"ansi"`` (text) or ``"rgb_array"`` (a top view).
        max_steps: time units per episode before truncation (``None``: never truncate).
        reward_attention: reward in a time unit with ``hear(attention)``.
        reward_other: reward in any other time unit.
        initial_focus: where the robot looks after ``reset`` (a place name); ``None`` draws
            it from the seeded generator. ``reset(options={"focus": P})`` overrides it.
        record_trace: keep :attr:`trace` (one :class:`StepRecord` per time unit).

    Attributes:
        caregiver: the caregiver model.
        world: the world (places, colours, kinds, toys, perception).
        places: every place, ``centre`` first.
        responses: action index -> response term.
        trace: the records of the current episode (a new list at each ``reset``).
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["ansi", "rgb_array"], "render_fps": 4}

    def __init__(self, caregiver: str | Caregiver = "paper",
                 caregiver_params: CaregiverParams | Mapping[str, Any] | None = None, *,
                 world: World | Mapping[str, Any] | None = None, observation: int = 0,
                 render_mode: str | None = None, max_steps: int | None = 500,
                 reward_attention: float = PAPER_REWARD.attention,
                 reward_other: float = PAPER_REWARD.other,
                 initial_focus: str | None = None, record_trace: bool = True) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise SimError(f"render_mode={render_mode!r}: use None, "
                           + " or ".join(repr(m) for m in self.metadata["render_modes"]))
        if max_steps is not None and (not isinstance(max_steps, int) or max_steps < 1):
            raise SimError(f"max_steps={max_steps!r}: use a whole number >= 1 or None")
        if observation not in (0, 1):
            raise SimError(f"observation={observation!r}: use 0 (v0) or 1 (v1)")
        self.caregiver = self._build_caregiver(caregiver, caregiver_params, world)
        params = self.caregiver.params
        if world is None:
            world = World(places=len(params.places), colours=len(params.toy_colours),
                          kinds=len(params.toy_kinds), toys=params.n_toys)
        elif isinstance(world, Mapping):
            world = World(**world)
        self.world = world
        n_toy = len(params.places)
        #: the geometry, when the places are a generated layout's (custom names have none).
        self.layout = layout(n_toy) if 2 <= n_toy and layout(n_toy).toy_places == \
            params.places else None
        self.places: tuple[str, ...] = self.caregiver.places
        self._index = {p: i for i, p in enumerate(self.places)}
        self.responses: tuple[tuple[str, str], ...] = tuple(("look", p) for p in self.places)
        self._poses: tuple[str, ...] = ("frontal",) + self.places[1:]
        #: the responses as terms and as text (indices go through the action space)
        self._actions: dict[Any, int] = {}
        for i, term in enumerate(self.responses):
            self._actions.update({term: i, f"look({term[1]})": i})
        self.initial_focus = self._place(initial_focus)
        self.render_mode = render_mode
        self.max_steps = max_steps
        self.reward_attention = float(reward_attention)
        self.reward_other = float(reward_other)
        self.record_trace = record_trace
        self.observation_version = observation
        colours, kinds = params.toy_colours, params.toy_kinds
        self._colour_code = {c: i + 1 for i, c in enumerate(colours)}
        self._colour_code[""] = 0
        self._kind_code = {k: i + 1 for i, k in enumerate(kinds)}
        self._kind_code[""] = 0
        self._scene = world.scene
        self._in_field = self._field_of_view(world.field) if world.scene else None
        n = len(self.places)
        self.action_space = spaces.Discrete(n)
        nvec = [n, 3, len(self._poses) + 1, len(colours) + 1, 2]
        if observation == 1:
            nvec.insert(4, len(kinds) + 1)
            if world.scene:
                nvec += [1 + max(1, len(colours)) * max(1, len(kinds))] * (n - 1)
        self.observation_space = spaces.MultiDiscrete(nvec)
        self.observation_fields = observation_fields(observation, self.places[1:], world.scene)
        self._cache: dict[tuple, tuple[np.ndarray, tuple]] = {}
        self.trace: list[StepRecord] = []
        self._metrics = GazeMetrics(params.contact_hold)
        self._t = 0
        self._focus = CENTRE
        self._record: StepRecord | None = None
        self._closed = False

    @staticmethod
    def _build_caregiver(caregiver: str | Caregiver, caregiver_params: Any,
                         world: World | Mapping[str, Any] | None) -> Caregiver:
        if isinstance(world, Mapping):
            world = World(**world)
        if isinstance(caregiver, Caregiver) or isinstance(caregiver_params, CaregiverParams):
            if isinstance(caregiver, Caregiver):
                if caregiver_params is not None:
                    raise SimError("caregiver_params only applies to a caregiver given by name")
                built = caregiver
            else:
                built = make_caregiver(caregiver, caregiver_params)
            if world is not None and built.params.places != world.layout.toy_places:
                raise SimError(f"the caregiver's places ({len(built.params.places)}) are not "
                               f"the world's ({world.places}): build its parameters with "
                               "World.caregiver_params()")
            return built
        if world is None:
            return make_caregiver(caregiver, caregiver_params)
        return make_caregiver(caregiver, world.caregiver_params(caregiver_params, caregiver))

    # ---- the Gymnasium API -----------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an interaction: the caregiver looks at the robot, no toys out.

        Args:
            seed: seeds the generator (same seed, same interaction for the same actions).
            options: ``{"focus": place}`` sets where the robot looks first;
                ``{"sequence_offset": k}`` starts an evaluation caregiver's target sequence
                at its k-th entry.

        Returns:
            The first observation and ``info`` (``percepts``, ``record``, ``toy_angles``).

        Raises:
            SimError: ``options`` is not a mapping (or None), names an unknown option, or
                gives a bad value.
        """
        if options is None:
            options = {}
        elif not isinstance(options, Mapping):
            raise SimError(f"options={options!r}: use a dict such as {{'focus': 'centre'}} "
                           f"(options: {', '.join(RESET_OPTIONS)}) or None")
        for key in options:
            if key not in RESET_OPTIONS:
                raise SimError(f"unknown reset option {key!r}"
                               f"{did_you_mean(str(key), RESET_OPTIONS)} (the options: "
                               f"{', '.join(RESET_OPTIONS)})")
        super().reset(seed=seed)
        focus = self._place(options.get("focus"))
        if focus is None:
            focus = self.initial_focus
        if focus is None:
            focus = int(self.np_random.integers(len(self.places)))
        offset = options.get("sequence_offset", 0)
        if not isinstance(offset, int) or isinstance(offset, bool) or offset < 0:
            raise SimError(f"sequence_offset={offset!r}: use a whole number >= 0")
        self.caregiver.sequence_offset = offset
        self._t = 0
        self._focus = focus
        self.caregiver.reset(self.np_random, focus)
        self.trace = []
        self._metrics = GazeMetrics(self.caregiver.params.contact_hold)
        obs, info = self._observe()
        return obs, info

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Emit a response and advance one time unit.

        Args:
            action: anything :attr:`action_space` contains (an int, a numpy integer, a 0-d
                integer array such as Stable-Baselines3's ``predict`` returns), or a
                response as a term (``("look", "left")``) or text (``"look(left)"``).

        Returns:
            ``(observation, reward, terminated, truncated, info)``; ``terminated`` is always
            False; ``info`` holds ``percepts``, ``record`` and ``toy_angles``, and at
            truncation the episode's metrics (see the module documentation).

        Raises:
            InvalidResponse: anything else.
        """
        focus = self._focus_of(action)
        if self._record is None:
            raise SimError("call reset() before step()")
        self._t += 1
        self._focus = focus
        self.caregiver.update(focus)
        obs, info = self._observe()
        attention = self.caregiver.attention
        reward = self.reward_attention if attention else self.reward_other
        truncated = self.max_steps is not None and self._t >= self.max_steps
        if truncated:
            info.update(self.metrics())
        return obs, reward, False, truncated, info

    def render(self) -> str | np.ndarray | None:
        """Draw the current time unit in the ``render_mode`` given at construction."""
        if self._record is None:
            raise SimError("call reset() before render()")
        if self.render_mode == "ansi":
            return render_text(self._record, self.places[1:])
        if self.render_mode == "rgb_array":
            return render_rgb(self._record, self.layout)
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
        return self.places[self._focus]

    @property
    def record(self) -> StepRecord | None:
        """The record of the current time unit (``None`` before ``reset``)."""
        return self._record

    @property
    def gaze_metrics(self) -> GazeMetrics:
        """The episode's :class:`GazeMetrics`, fed every time unit (CGI by place too)."""
        return self._metrics

    def metrics(self, first: int | None = None) -> dict[str, float | int]:
        """The episode's metrics so far (:meth:`GazeMetrics.summary`): ``cgi`` (relrl's),
        ``cgi_literal`` (Eq. 5 as written), ``eye_contacts`` of ``opportunities``, ..."""
        return self._metrics.summary(first)

    def toy_angles(self) -> tuple[tuple[str, float], ...]:
        """For each toy out, ``(place, degrees)`` the robot's head must turn to focus it."""
        if self.layout is None:
            return ()
        row = self.layout.angle_between[self._focus]
        return tuple((place, row[self._index[place]]) for place, _ in self.caregiver.toys)

    # ---- internals -------------------------------------------------------------------------

    def _focus_of(self, action: Any) -> int:
        """The place index of ``action`` (see :meth:`step`)."""
        if self.action_space.contains(action):
            return int(action) - int(self.action_space.start)
        if isinstance(action, (str, tuple)):
            try:
                return self._actions[action]
            except (KeyError, TypeError):   # a tuple may hold what cannot be hashed
                pass
        looks = [f"look({p})" for p in self.places]
        shown = ", ".join(looks) if len(looks) <= 10 else f"{looks[0]} ... {looks[-1]}"
        raise InvalidResponse(
            f"not a response of the SIS: {action!r}"
            f"{did_you_mean(str(action), looks)}; use an action index "
            f"0-{len(looks) - 1} (an int, a numpy integer or a 0-d integer array) or one "
            f"of {shown}")

    def _place(self, name: str | None) -> int | None:
        if name is None:
            return None
        try:
            return self._index[name]
        except (KeyError, TypeError):
            shown = ", ".join(self.places) if len(self.places) <= 10 else \
                f"{self.places[0]}, {self.places[1]} ... {self.places[-1]}"
            raise SimError(f"unknown place {name!r}{did_you_mean(str(name), self.places)}; "
                           f"use one of {shown}") from None

    def _field_of_view(self, field: float) -> tuple[tuple[int, ...], ...]:
        """For each focus, the toy places within ``field`` degrees of it."""
        if self.layout is None:
            raise SimError("whole-scene perception needs a world of at least 2 places")
        angles = self.layout.angle_between
        n = len(self.places)
        return tuple(tuple(j for j in range(1, n) if angles[i][j] <= field) for i in range(n))

    def _observe(self) -> tuple[np.ndarray, dict[str, Any]]:
        cg = self.caregiver
        focus, attention = self._focus, cg.attention
        what = cg.gaze if focus == CENTRE else (cg.toy_at[focus], cg.kind_at[focus])
        key: tuple = (focus, what, attention)
        if self._scene:
            key += (tuple((j, cg.toy_at[j], cg.kind_at[j]) for j in self._in_field[focus]
                          if cg.toy_at[j] is not None),)
        cached = self._cache.get(key)
        if cached is None:
            cached = self._cache[key] = self._encode(*key)
        obs, percepts = cached
        obs = obs.copy()  # users keep observations: never hand out the same array twice
        target = cg.target
        places = self.places
        rec = StepRecord(self._t, places[focus], self._poses[cg.gaze], cg.phase,
                         cg.opportunity, cg.trial, cg.toys,
                         places[target] if target >= 0 else None, attention, cg.contact,
                         cg.kinds)
        self._record = rec
        self._metrics.add(rec)
        if self.record_trace:
            self.trace.append(rec)
        info = {"percepts": list(percepts), "record": rec,
                "toy_angles": self.toy_angles() if cg.toys else ()}
        return obs, info

    def _encode(self, focus: int, what: Any, attention: bool, scene: tuple = ()
                ) -> tuple[np.ndarray, tuple]:
        """Observation and percepts of one (focus, thing in view, attention, scene)."""
        place = self.places[focus]
        kind = 0
        if focus == CENTRE:
            percepts = [_SEE_FACE, ("pose", "face", self._poses[what])]
            seen, pose, colour = 1, 1 + what, 0
        elif what[0] is None:
            percepts = [_SEE_ENV]
            seen, pose, colour = 0, 0, 0
        else:
            percepts = [_SEE_TOY, ("at", "toy", place)]
            if what[0]:
                percepts.append(("colour", "toy", what[0]))
            if what[1]:
                percepts.append(("kind", "toy", what[1]))
            seen, pose = 2, 0
            colour, kind = self._colour_code[what[0]], self._kind_code[what[1]]
        for j, c, k in scene:
            percepts.append(("in_view", self.places[j], c or "none", k or "none"))
        percepts.append(("at", place))
        if attention:
            percepts.append(_HEAR)
        fields = [focus, seen, pose, colour, int(attention)]
        if self.observation_version == 1:
            fields.insert(4, kind)
            if self._scene:
                n_kinds = max(1, len(self._kind_code) - 1)
                cells = [0] * (len(self.places) - 1)
                for j, c, k in scene:
                    ci = max(0, self._colour_code[c] - 1)
                    ki = max(0, self._kind_code[k] - 1)
                    cells[j - 1] = 1 + ci * n_kinds + ki
                fields += cells
        return np.array(fields, dtype=np.int64), tuple(percepts)


class SharedAttentionEnvV1(SharedAttentionEnv):
    """``relrl/SharedAttention-v1``: :class:`SharedAttentionEnv` with the version-1
    observation (the toy's kind and, in whole-scene worlds, every toy in view)."""

    def __init__(self, *args: Any, observation: int = 1, **kwargs: Any) -> None:
        super().__init__(*args, observation=observation, **kwargs)
