"""Caregiver models of the Social Interactive Simulator, in a registry looked up by name.

A caregiver is a small state machine advanced once per time unit by the simulator
(:class:`relrl.sim.sis.SharedAttentionEnv`). It decides where it looks, which toys are where
and when it gives attention (the robot's reinforcer, ``hear(attention)``).

The paper's protocol (:class:`ProtocolCaregiver`; da Silva & Romero 2012, section 5.1) is a
cycle of three phases:

``engage``
    The caregiver looks at the robot (its face is ``frontal`` to the robot) and waits for eye
    contact: the robot's focus on the caregiver's face for ``contact_hold`` (3) consecutive
    time units. Each entry into this phase is one *eye-contact opportunity*. The caregiver
    gives attention **at most once per opportunity**: when eye contact is established
    (``attention_on_contact``, the default), or already in the first time unit the robot
    looks at its face (``attention_during_gaze``). The 2012 caregiver
    (``attention_per_unit``, the ``paper_2012`` model) attends instead in every time unit of
    mutual gaze while it waits, as the paper's figures imply; looking away and back then
    farms attention. If eye contact is not established within
    ``contact_timeout`` time units the opportunity is missed and a new one starts (the
    caregiver keeps looking at the robot; toys only come after eye contact).
``present``
    The time unit after eye contact the toys appear (``n_toys`` of them, at empty places drawn
    with ``placement`` weights; the first is the target, the others distractors; each gets a
    colour from ``toy_colours`` and a kind from ``toy_kinds``). The caregiver keeps looking at the
    robot for ``latency`` time units (0: it turns in the same time unit).
``attend``
    The caregiver looks at the target (with probability ``reliability``; otherwise at one of
    the other toy places, uniformly) and waits ``timeout`` time units after turning. In
    the time unit the robot's focus is on the target, the caregiver gives attention; both look
    at the toy in that time unit. In the next time unit the toys are gone and the caregiver
    looks at the robot again (a new ``engage``). On timeout, or with ``single_look`` after the
    robot's first look away from the face, it also goes back to ``engage`` without attention.

Register other models with :func:`register_caregiver`; build one with
:func:`make_caregiver`.
"""

from __future__ import annotations

import abc
import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from relrl.sim.errors import CaregiverConfigError, UnknownCaregiver, did_you_mean
from relrl.sim.places import CENTRE, MAX_PLACES, TOY_PLACES

__all__ = [
    "ATTEND",
    "ENGAGE",
    "EVALUATION_SEQUENCE",
    "PRESENT",
    "Caregiver",
    "CaregiverParams",
    "ProtocolCaregiver",
    "caregiver_names",
    "evaluation_sequence",
    "make_caregiver",
    "preset_params",
    "register_caregiver",
]

#: phase names (the values of :attr:`Caregiver.phase`).
ENGAGE, PRESENT, ATTEND = "engage", "present", "attend"

#: a fixed, balanced sequence of target places for evaluation runs: each toy place four
#: times, never twice in a row, also across the wrap from the end to the start (the paper's
#: "pre-established sequence"; its own is unknown).
EVALUATION_SEQUENCE: tuple[str, ...] = (
    "left", "down", "right_down", "left_down", "right",
    "down", "left_down", "right", "left", "right_down",
    "right", "left", "left_down", "down", "right_down",
    "left_down", "right_down", "down", "left", "right",
)


def evaluation_sequence(places: tuple[str, ...] = TOY_PLACES, rounds: int = 4
                        ) -> tuple[str, ...]:
    """A fixed, balanced sequence of evaluation targets over ``places``.

    Each place appears ``rounds`` times, never twice in a row (nor across the wrap from the
    end to the start). The paper's five places give :data:`EVALUATION_SEQUENCE`; other worlds
    get rounds shuffled by a generator seeded with the number of places, so the sequence is
    the same on every machine.
    """
    places = tuple(places)
    if places == TOY_PLACES and rounds == 4:
        return EVALUATION_SEQUENCE
    if len(places) == 1:
        return places * rounds
    rng = np.random.default_rng(len(places))
    while True:  # draw rounds until no place follows itself (cyclically); a few tries
        out = [places[i] for _ in range(rounds) for i in rng.permutation(len(places))]
        if all(out[k] != out[k - 1] for k in range(len(out))):
            break
    return tuple(out)


@dataclass(frozen=True)
class CaregiverParams:
    """What a researcher varies about the caregiver. Every time is in time units (steps).

    Attributes:
        n_toys: toys put out per trial (1 to the number of places); the first is the target,
            the others are distractors (the caregiver never means them).
        placement: weight of each toy place for placing a toy (missing places weigh 0); the
            target is drawn with these weights, then each distractor among the places still
            empty (uniformly among them if those all weigh 0). ``None``: every place alike.
        toy_colours: colours given to the toys of a trial in a random order (cycled if there
            are more toys than colours); the robot perceives ``colour(toy, C)``. Empty: toys
            have no colour and no colour percept.
        toy_kinds: kinds of toy (``ball``, ``car``, ...) dealt to a trial's toys like the
            colours; the robot perceives ``kind(toy, K)``. Empty (the paper's world): toys
            have no kind and no kind percept.
        places: the toy places of the world, from the robot's left to its right (see
            :func:`relrl.sim.places.layout`); ``centre`` is always the caregiver's face.
        reliability: probability that the caregiver looks at the target; otherwise it looks
            at one of the other toy places, uniformly (with five places 0.2 makes its gaze
            uninformative).
        latency: time units the caregiver keeps looking at the robot after placing the toys
            before it turns to the target (0: places and turns in the same time unit).
        timeout: time units the caregiver waits, after turning, for the robot to look at the
            target before it removes the toys and looks back at the robot.
        contact_hold: consecutive time units of the robot looking at the caregiver's face
            that make eye contact (the paper: 3).
        contact_timeout: time units an eye-contact opportunity lasts before it is missed and
            a new one starts; ``None`` waits for ever.
        attention_on_contact: give attention in the time unit eye contact is established
            (unless it was given already in this opportunity).
        attention_during_gaze: give attention already in the first time unit of mutual gaze
            of each opportunity (the robot on the caregiver's face, the caregiver looking at
            the robot), as Triesch et al.'s caregiver rewards looking at its face. Either way
            the caregiver attends at most once per opportunity: looking away and back cannot
            farm attention.
        attention_per_unit: give attention in every time unit of mutual gaze while waiting
            for eye contact (the robot on the caregiver's face, the caregiver looking at the
            robot), with no limit per opportunity: the paper's 2012 caregiver, under which
            looking at the face pays at once and looking away and back farms attention.
            Supersedes ``attention_during_gaze``; eye contact itself gives nothing more.
        single_look: end a trial (no attention) at the robot's first look, after the turn, at
            anything but the face or the target — one try per trial, as the paper's
            evaluation reads.
        target_sequence: evaluation mode: the target's place in trial k is
            ``target_sequence[k % len]`` (from the start of each episode); distractors are
            still drawn with ``placement``. ``None``: the target is drawn too.
    """

    n_toys: int = 2
    placement: Mapping[str, float] | None = None
    toy_colours: tuple[str, ...] = ("red", "green")
    toy_kinds: tuple[str, ...] = ()
    places: tuple[str, ...] = TOY_PLACES
    reliability: float = 1.0
    latency: int = 0
    timeout: int = 5
    contact_hold: int = 3
    contact_timeout: int | None = 10
    attention_on_contact: bool = True
    attention_during_gaze: bool = False
    attention_per_unit: bool = False
    single_look: bool = False
    target_sequence: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        def bad(name: str, why: str) -> CaregiverConfigError:
            value = getattr(self, name)
            return CaregiverConfigError(f"caregiver parameter {name}={value!r}: {why}")

        places = tuple(self.places) if isinstance(self.places, list | tuple) else None
        if (not places or len(places) > MAX_PLACES or "centre" in places
                or len(set(places)) != len(places)
                or not all(isinstance(x, str) and x for x in places)):
            raise bad("places", f"use 1 to {MAX_PLACES} distinct place names other than "
                                "'centre', e.g. relrl.sim.places.place_names(9)")
        object.__setattr__(self, "places", places)
        if (not isinstance(self.n_toys, int) or isinstance(self.n_toys, bool)
                or not 1 <= self.n_toys <= len(places)):
            raise bad("n_toys", f"use a whole number from 1 to {len(places)}")
        if self.placement is None:
            object.__setattr__(self, "placement", {p: 1.0 for p in places})
        if not isinstance(self.placement, Mapping):
            raise bad("placement", "use a mapping place -> weight, e.g. {'left': 2.0}")
        weights = {}
        for place, weight in self.placement.items():
            if place not in places:
                shown = ", ".join(places) if len(places) <= 9 else \
                    f"{places[0]} ... {places[-1]}"
                raise bad("placement", f"unknown place {place!r}{did_you_mean(place, places)}"
                          f" (places: {shown})")
            if not isinstance(weight, int | float) or weight < 0 or math.isnan(weight):
                raise bad("placement", f"the weight of {place!r} must be a number >= 0")
            weights[place] = float(weight)
        if sum(w > 0 for w in weights.values()) < 1:
            raise bad("placement", "give at least one place a positive weight")
        object.__setattr__(self, "placement", {p: weights.get(p, 0.0) for p in places})
        for name, example in (("toy_colours", "('red', 'green')"),
                              ("toy_kinds", "('ball', 'car')")):
            value = getattr(self, name)
            if isinstance(value, str) or not isinstance(value, list | tuple) or not all(
                    isinstance(c, str) and c for c in value):
                raise bad(name, f"use a sequence of non-empty names, e.g. {example}")
            object.__setattr__(self, name, tuple(value))
        if not isinstance(self.reliability, int | float) or not 0.0 <= self.reliability <= 1.0:
            raise bad("reliability", "use a probability from 0 to 1")
        for name, low in (("latency", 0), ("timeout", 1), ("contact_hold", 1)):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < low:
                raise bad(name, f"use a whole number >= {low}")
        if self.contact_timeout is not None and (
                not isinstance(self.contact_timeout, int)
                or self.contact_timeout < self.contact_hold):
            raise bad("contact_timeout", f"use None or a whole number >= contact_hold "
                                         f"({self.contact_hold})")
        if self.target_sequence is not None:
            seq = tuple(self.target_sequence)
            if not seq:
                raise bad("target_sequence", "use None or a non-empty sequence of places")
            for place in seq:
                if place not in places:
                    raise bad("target_sequence", f"unknown place {place!r}"
                              f"{did_you_mean(str(place), places)}")
            object.__setattr__(self, "target_sequence", seq)

    def replace(self, **overrides: Any) -> CaregiverParams:
        """Return a copy with some parameters changed (names are checked)."""
        names = {f.name for f in dataclasses.fields(self)}
        for key in overrides:
            if key not in names:
                raise CaregiverConfigError(
                    f"unknown caregiver parameter {key!r}{did_you_mean(key, names)} "
                    f"(parameters: {', '.join(sorted(names))})")
        return dataclasses.replace(self, **overrides)

    def for_evaluation(self, sequence: tuple[str, ...] | None = None) -> CaregiverParams:
        """Return a copy in evaluation mode: targets from ``sequence`` (default: the
        balanced :func:`evaluation_sequence` of this caregiver's places)."""
        if sequence is None:
            sequence = evaluation_sequence(self.places)
        return self.replace(target_sequence=tuple(sequence))

    def to_dict(self) -> dict[str, Any]:
        """The parameters as plain JSON-ready values."""
        out = dataclasses.asdict(self)
        out["placement"] = dict(self.placement)
        out["toy_colours"] = list(self.toy_colours)
        out["toy_kinds"] = list(self.toy_kinds)
        out["places"] = list(self.places)
        if self.target_sequence is not None:
            out["target_sequence"] = list(self.target_sequence)
        return out


class Caregiver(abc.ABC):
    """A caregiver model: the simulator reads these attributes after each update.

    Attributes:
        params: the parameters it was built with.
        places: every place of its world, ``centre`` first (``("centre",) + params.places``).
        phase: the current phase name (``engage``, ``present``, ``attend`` for the protocol).
        gaze: index in :attr:`places` of where it looks; ``CENTRE`` (0) means at the robot
            (the robot then sees a ``frontal`` face).
        toy_at: for each place index, the colour of the toy there (``""`` for a toy without
            colour), or ``None`` when the place is empty.
        kind_at: for each place index, the kind of the toy there (``""`` without kinds).
        toys: the toys out now as ``(place, colour)`` pairs, target first.
        kinds: the kinds of :attr:`toys`, in the same order (empty without kinds).
        target: place index of the target toy, or -1 when there is none.
        opportunity: index of the current eye-contact opportunity (from 0).
        trial: index of the current (or last) toy trial (-1 before the first).
        contact: eye contact was established in this time unit.
        attention: attention is given in this time unit.
        sequence_offset: evaluation mode: trial *k* of an episode takes the target at
            ``target_sequence[(k + sequence_offset) % len]`` (set before ``reset``).
    """

    def __init__(self, params: CaregiverParams) -> None:
        self.params = params
        self.places: tuple[str, ...] = ("centre",) + params.places
        self._index = {name: i for i, name in enumerate(self.places)}
        self.phase = ENGAGE
        self.gaze = CENTRE
        self.toy_at: list[str | None] = [None] * len(self.places)
        self.kind_at: list[str] = [""] * len(self.places)
        self.toys: tuple[tuple[str, str], ...] = ()
        self.kinds: tuple[str, ...] = ()
        self.target = -1
        self.opportunity = 0
        self.trial = -1
        self.contact = False
        self.attention = False
        self.sequence_offset = 0

    @abc.abstractmethod
    def reset(self, rng: np.random.Generator, focus: int) -> None:
        """Start an interaction; ``focus`` is the robot's first focus (a place index)."""

    @abc.abstractmethod
    def update(self, focus: int) -> None:
        """Advance one time unit; ``focus`` is where the robot looks in it."""


class ProtocolCaregiver(Caregiver):
    """The paper's protocol (see the module documentation)."""

    def reset(self, rng: np.random.Generator, focus: int) -> None:
        """Start with opportunity 0 and judge the robot's first focus."""
        self._rng = rng
        self._next: Callable[[], None] | None = None
        self._age = 0
        self._streak = 0
        self._attended = False
        self.opportunity = -1
        self.trial = -1
        self._enter_engage()
        self._judge(focus)

    def update(self, focus: int) -> None:
        """Enter the phase decided last time unit (if any), then judge the robot's focus."""
        enter = self._next
        if enter is None:
            self._age += 1
        else:
            self._next = None
            enter()
        self._judge(focus)

    # ---- phases ----------------------------------------------------------------------------

    def _enter_engage(self) -> None:
        if self.toys:
            for place, _ in self.toys:
                i = self._index[place]
                self.toy_at[i] = None
                self.kind_at[i] = ""
            self.toys = ()
            self.kinds = ()
        self.target = -1
        self.gaze = CENTRE
        self.phase = ENGAGE
        self.opportunity += 1
        self._streak = 0
        self._age = 0
        self._attended = False

    def _enter_present(self) -> None:
        self._place_toys()
        self.phase = PRESENT
        self._age = 0
        if self.params.latency == 0:
            self._enter_attend()

    def _enter_attend(self) -> None:
        p = self.params
        self.phase = ATTEND
        self._age = 0
        # One draw per trial whatever the reliability, so runs that differ only in
        # reliability see the same toys (common random numbers).
        u, v = self._rng.random(), self._rng.random()
        if u < p.reliability:
            self.gaze = self.target
        else:
            others = [i for i in range(1, len(self.places)) if i != self.target]
            self.gaze = others[min(int(v * len(others)), len(others) - 1)]

    def _judge(self, focus: int) -> None:
        p = self.params
        self.contact = False
        self.attention = False
        phase = self.phase
        if phase == ENGAGE:
            self._streak = self._streak + 1 if focus == CENTRE else 0
            if focus == CENTRE and (p.attention_per_unit or (p.attention_during_gaze
                                                             and not self._attended)):
                self.attention = self._attended = True
            if self._streak >= p.contact_hold:
                self.contact = True
                if p.attention_on_contact and not self._attended:
                    self.attention = self._attended = True
                self._next = self._enter_present
            elif p.contact_timeout is not None and self._age + 1 >= p.contact_timeout:
                self._next = self._enter_engage  # missed: a new opportunity starts
        elif phase == PRESENT:
            if self._age + 1 >= p.latency:
                self._next = self._enter_attend
        elif phase == ATTEND:
            if focus == self.target:
                self.attention = True
                self._next = self._enter_engage
            elif (p.single_look and self._age > 0 and focus != CENTRE) or self._age >= p.timeout:
                self._next = self._enter_engage

    # ---- toys ------------------------------------------------------------------------------

    def _draw(self, free: list[int]) -> int:
        """Draw a place index from ``free`` with the placement weights."""
        placement, places = self.params.placement, self.places
        weights = [placement[places[i]] for i in free]
        total = sum(weights)
        if total <= 0:
            weights, total = [1.0] * len(free), float(len(free))
        x = self._rng.random() * total
        for place, w in zip(free, weights, strict=True):
            x -= w
            if x < 0:
                return place
        return max(pl for pl, w in zip(free, weights, strict=True) if w > 0)  # rounding

    def _deal(self, names: tuple[str, ...], n: int) -> list[str]:
        """``n`` names dealt from ``names`` in a random order (cycled), or ``""`` each."""
        if not names:
            return [""] * n
        order = self._rng.permutation(len(names))
        return [names[order[k % len(names)]] for k in range(n)]

    def _place_toys(self) -> None:
        p = self.params
        self.trial += 1
        free = list(range(1, len(self.places)))
        if p.target_sequence is not None:
            seq = p.target_sequence
            target = self._index[seq[(self.trial + self.sequence_offset) % len(seq)]]
            self._rng.random()  # keep the random stream aligned with the drawing mode
        else:
            target = self._draw(free)
        free.remove(target)
        chosen = [target]
        for _ in range(p.n_toys - 1):
            place = self._draw(free)
            free.remove(place)
            chosen.append(place)
        colours = self._deal(p.toy_colours, len(chosen))
        kinds = self._deal(p.toy_kinds, len(chosen)) if p.toy_kinds else [""] * len(chosen)
        for place, colour, kind in zip(chosen, colours, kinds, strict=True):
            self.toy_at[place] = colour
            self.kind_at[place] = kind
        self.toys = tuple((self.places[pl], c) for pl, c in zip(chosen, colours, strict=True))
        self.kinds = tuple(kinds) if p.toy_kinds else ()
        self.target = target
        self.gaze = CENTRE


# ---- registry ------------------------------------------------------------------------------

_REGISTRY: dict[str, tuple[Callable[[CaregiverParams], Caregiver], CaregiverParams, str]] = {}


def register_caregiver(name: str, factory: Callable[[CaregiverParams], Caregiver],
                       params: CaregiverParams | None = None, doc: str = "") -> None:
    """Register a caregiver model under ``name``.

    Args:
        name: the name :func:`make_caregiver` and the simulator look it up by.
        factory: builds the caregiver from its parameters (e.g. a :class:`Caregiver` class).
        params: the preset's default parameters.
        doc: one line describing the model.
    """
    _REGISTRY[name] = (factory, params or CaregiverParams(), doc)


def preset_params(name: str = "paper") -> CaregiverParams:
    """The default parameters of a registered caregiver model.

    Raises:
        UnknownCaregiver: no model has this name (the message suggests the closest).
    """
    return _lookup(name)[1]


def _lookup(name: str) -> tuple[Callable[[CaregiverParams], Caregiver], CaregiverParams, str]:
    try:
        return _REGISTRY[name]
    except (KeyError, TypeError):
        raise UnknownCaregiver(f"unknown caregiver model {name!r}"
                               f"{did_you_mean(str(name), _REGISTRY)}"
                               f" (models: {', '.join(_REGISTRY)})") from None


def caregiver_names() -> dict[str, str]:
    """Return registered name -> one-line description."""
    return {name: doc for name, (_, _, doc) in _REGISTRY.items()}


def make_caregiver(name: str = "paper", params: CaregiverParams | Mapping[str, Any] | None = None
                   ) -> Caregiver:
    """Build a registered caregiver model.

    Args:
        name: a registered name (see :func:`caregiver_names`).
        params: full parameters, or a mapping of overrides of the preset's parameters.

    Raises:
        UnknownCaregiver: no model has this name (the message suggests the closest).
        CaregiverConfigError: a parameter is unknown or has a bad value.
    """
    factory, preset, _ = _lookup(name)
    if isinstance(params, CaregiverParams):
        return factory(params)
    return factory(preset.replace(**dict(params or {})))


register_caregiver("paper", ProtocolCaregiver, CaregiverParams(),
                   "the paper's protocol: two toys, always looks at the target")
register_caregiver("unreliable", ProtocolCaregiver, CaregiverParams(reliability=0.5),
                   "the paper's protocol, looking at the target only half the time")
register_caregiver("random", ProtocolCaregiver, CaregiverParams(reliability=0.2),
                   "the paper's protocol with an uninformative gaze (any toy place alike)")
register_caregiver("paper_2012", ProtocolCaregiver, CaregiverParams(attention_per_unit=True),
                   "the 2012 paper's caregiver: attention in every time unit of mutual gaze")
register_caregiver("one_toy", ProtocolCaregiver, CaregiverParams(n_toys=1),
                   "the paper's protocol with one toy, as in the head experiment")
