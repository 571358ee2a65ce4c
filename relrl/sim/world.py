"""Worlds that grow: the Social Interactive Simulator with more places, toys and colours.

A :class:`World` describes what the simulator and its domain share: ``P`` toy places (the
caregiver's gaze directions; the paper has 5), ``C`` toy colours, ``K`` toy kinds, how many
toys a trial puts out (the target and its distractors), and whether the robot perceives the
whole scene (every toy in its field of view) or only its focus. Everything else about the
caregiver (reliability, latency, timeouts) stays in
:class:`~relrl.sim.caregiver.CaregiverParams`.

The world builds the rest, so nothing is copied by hand::

    world = World(places=9, colours=3, scene=True)
    env = SharedAttentionEnv(world=world, caregiver_params={"reliability": 0.8})
    path = world.write_domain("runs/worlds")                     # its Prolog domain

``World()`` is the paper's world: :meth:`World.domain_text` then declares the same stimuli,
facts and responses, in the same order (so the same state codes), as
``examples/domains/sis.pl``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from perception.vocabulary import Vocabulary, sis_vocabulary
from relrl.outdir import write_atomic
from relrl.sim.caregiver import CaregiverParams, preset_params
from relrl.sim.domain import domain_text
from relrl.sim.errors import SimError, did_you_mean
from relrl.sim.places import MAX_PLACES, Layout, layout

__all__ = ["COLOUR_NAMES", "KIND_NAMES", "World", "colour_names", "kind_names"]

#: colour names dealt first (more colours are ``colour_7``, ``colour_8``, ...).
COLOUR_NAMES: tuple[str, ...] = ("red", "green", "blue", "yellow", "orange", "purple")
#: kind names dealt first (more kinds are ``kind_7``, ...).
KIND_NAMES: tuple[str, ...] = ("ball", "car", "duck", "block", "ring", "bell")


def _names(base: tuple[str, ...], prefix: str, n: int) -> tuple[str, ...]:
    return base[:n] + tuple(f"{prefix}_{k}" for k in range(len(base) + 1, n + 1))


def colour_names(n: int) -> tuple[str, ...]:
    """The first ``n`` colour names (:data:`COLOUR_NAMES`, then ``colour_7``, ...)."""
    return _names(COLOUR_NAMES, "colour", n)


def kind_names(n: int) -> tuple[str, ...]:
    """The first ``n`` kind names (:data:`KIND_NAMES`, then ``kind_7``, ...)."""
    return _names(KIND_NAMES, "kind", n)


@dataclass(frozen=True)
class World:
    """The size of a Social Interactive Simulator world.

    Attributes:
        places: ``P``, the toy places (gaze directions besides the caregiver's face), 2 to 257.
        colours: ``C``, toy colours (0: toys have no colour and no colour percept).
        kinds: ``K``, toy kinds (0: toys have no kind, as in the paper).
        toys: toys per trial: the target and ``toys - 1`` distractors the caregiver does not
            mean (1 to ``places``).
        scene: whole-scene perception: besides its focus the robot perceives every toy in
            its field of view, ``in_view(Place, Colour, Kind)``; False: only its focus (the
            paper).
        field: half-angle of the field of view in degrees (with ``scene``): a toy is in view
            when the angle between it and the robot's focus is at most this. 60 sees the
            whole table from the caregiver's face.
    """

    places: int = 5
    colours: int = 2
    kinds: int = 0
    toys: int = 2
    scene: bool = False
    field: float = 60.0

    def __post_init__(self) -> None:
        def whole(name: str, low: int, high: int) -> None:
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or not low <= value <= high:
                raise SimError(f"world {name}={value!r}: use a whole number from {low} to "
                               f"{high}")

        whole("places", 2, MAX_PLACES)
        whole("colours", 0, 99)
        whole("kinds", 0, 99)
        whole("toys", 1, self.places)
        if not isinstance(self.scene, bool):
            raise SimError(f"world scene={self.scene!r}: use true or false")
        if (not isinstance(self.field, int | float) or isinstance(self.field, bool)
                or math.isnan(self.field) or not 0 < self.field <= 180):
            raise SimError(f"world field={self.field!r}: use an angle in degrees, 0 < field "
                           "<= 180")
        object.__setattr__(self, "field", float(self.field))

    # ---- names and geometry ----------------------------------------------------------------

    @property
    def layout(self) -> Layout:
        """The places and angles of this world."""
        return layout(self.places)

    @property
    def colour_names(self) -> tuple[str, ...]:
        """The toy colours."""
        return colour_names(self.colours)

    @property
    def kind_names(self) -> tuple[str, ...]:
        """The toy kinds."""
        return kind_names(self.kinds)

    @property
    def name(self) -> str:
        """A short name, e.g. ``p9-c3-k0-t2-scene``: the domain file's stem."""
        return (f"sis-p{self.places}-c{self.colours}-k{self.kinds}-t{self.toys}"
                + (f"-scene{self.field:g}" if self.scene else ""))

    # ---- building the simulator and the domain ---------------------------------------------

    def caregiver_params(self, overrides: Mapping[str, Any] | None = None,
                         preset: str = "paper") -> CaregiverParams:
        """The caregiver's parameters in this world: a registered preset with this world's
        places, colours, kinds and toys per trial, then ``overrides`` (reliability, ...)."""
        base = preset_params(preset).replace(
            places=self.layout.toy_places, placement=None, toy_colours=self.colour_names,
            toy_kinds=self.kind_names, n_toys=self.toys)
        return base.replace(**dict(overrides or {}))

    def domain_text(self) -> str:
        """This world's domain file (see :mod:`relrl.sim.domain`)."""
        return domain_text(self)

    def write_domain(self, folder: str | Path, stem: str | None = None) -> Path:
        """Write this world's domain to ``folder/STEM.pl``, ``STEM`` this world's
        :attr:`name` by default (unchanged files are left alone; a new one appears whole,
        through a rename). Returns the path."""
        path = Path(folder) / f"{stem or self.name}.pl"
        text = self.domain_text()
        if path.is_file() and not path.is_symlink() and path.read_text() == text:
            return path
        return write_atomic(path, text)

    def vocabulary(self) -> Vocabulary:
        """The percepts this world produces, as a
        :class:`perception.vocabulary.Vocabulary` (what ``relrl check --world`` compares a
        domain with): the simulator's for these places, plus ``kind(toy, K)`` and
        ``in_view(P, C, K)`` where the world has them."""
        places = self.layout.places
        base = sis_vocabulary(places, name=self.name,
                              description=f"the simulator, {self.places} toy places")
        extra: tuple = ()
        if self.kinds:
            extra += (("kind", "toy", self.kind_names),)
        if self.scene:
            extra += (("in_view", places[1:], self.colour_names or ("none",),
                       self.kind_names or ("none",)),)
        return Vocabulary(base.name, base.description, base.patterns + extra)

    # ---- (de)serialising -------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return dataclasses.asdict(self)

    def replace(self, **changes: Any) -> World:
        """A copy with some fields changed (names are checked)."""
        names = [f.name for f in dataclasses.fields(self)]
        for key in changes:
            if key not in names:
                raise SimError(f"unknown world field {key!r}{did_you_mean(key, names)} "
                               f"(fields: {', '.join(names)})")
        return dataclasses.replace(self, **changes)

    @classmethod
    def parse(cls, text: str) -> World:
        """A world from ``"places=9,colours=3,scene=true"`` (unnamed fields keep defaults).

        Raises:
            SimError: an unknown field or a bad value, named.
        """
        changes: dict[str, Any] = {}
        for item in (x.strip() for x in text.split(",")):
            if not item:
                continue
            key, sep, value = item.partition("=")
            key, value = key.strip(), value.strip()
            if not sep:
                raise SimError(f"bad world setting {item!r}: use NAME=VALUE, e.g. places=9")
            if key == "scene":
                if value.lower() not in ("true", "false", "1", "0", "yes", "no"):
                    raise SimError(f"world scene={value!r}: use true or false")
                changes[key] = value.lower() in ("true", "1", "yes")
            elif key == "field":
                try:
                    changes[key] = float(value)
                except ValueError:
                    raise SimError(f"world field={value!r}: use an angle in degrees") from None
            else:
                try:
                    changes[key] = int(value)
                except ValueError:
                    changes[key] = value  # the field's check names it
        return cls().replace(**changes)
