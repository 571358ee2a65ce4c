"""The vocabulary every package of the project shares: places, head poses, colours, fruits, and
what each world perceives.

Perception owns the percept vocabulary, and this is its one module: it imports nothing but
the standard library (importing it does not import OpenCV or numpy), so ``head`` reads its
place names from here without importing relrl, and relrl reads them from here too.
Everything is in the robot's frame: ``left`` is the robot's left, which is also the left of
the camera image.

Places and poses
    :data:`PLACES` are where the head can look, ``centre`` (the caregiver's face) first; the
    index of a place is the simulator's action number. Objects (toys, fruits) appear at the
    :data:`OBJECT_PLACES`. :data:`POSES` are the head-pose classes perception tells apart
    (experiment 2): ``left_1``/``left_2`` a slight/strong turn of the caregiver's face towards
    the robot's left, ``right_*`` the mirror, ``down`` towards the table. :data:`GAZE_POSE` is
    the pose a caregiver shows while looking at each place.

Worlds
    Each world (:data:`WORLDS`) perceives its own percepts, declared as a
    :class:`Vocabulary`. The two differ where a domain author can trip:

    * ``sis`` (the Social Interactive Simulator, experiment 1) perceives where the caregiver
      looks as a **place**: ``pose(face, left)``, with ``frontal`` for the robot;
    * ``episodes`` (episode scripts, the camera) and ``fruits`` (experiment 2, a narrower
      ``episodes``) perceive the caregiver's **head-pose class**: ``pose(face, left_2)``.

    A domain fact written for one world never holds in the other; ``relrl check --world``
    warns about such facts. Worlds generated with other places (a growing simulator) build
    their vocabulary with :func:`sis_vocabulary`.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from itertools import product
from typing import Any

__all__ = [
    "ANY",
    "COLOURS",
    "FRUIT_COLOURS",
    "GAZE_POSE",
    "HUES",
    "OBJECT_PLACES",
    "PLACES",
    "POSES",
    "SIS_POSES",
    "WORLDS",
    "Vocabulary",
    "episodes_vocabulary",
    "sis_vocabulary",
    "world",
]

#: where the head can look; ``centre`` (index 0) is the caregiver's face.
PLACES: tuple[str, ...] = ("centre", "left", "left_down", "down", "right_down", "right")
#: where objects (toys, fruits) can be: every place but the caregiver's face.
OBJECT_PLACES: tuple[str, ...] = PLACES[1:]

#: the head-pose classes perception tells apart (experiment 2; see the module docstring).
POSES: tuple[str, ...] = ("frontal", "left_1", "left_2", "right_1", "right_2", "down")
#: the pose a caregiver shows while looking at each place.
GAZE_POSE: dict[str, str] = {
    "centre": "frontal",
    "left": "left_2",
    "left_down": "left_1",
    "down": "down",
    "right_down": "right_1",
    "right": "right_2",
}
#: what the simulator perceives as the caregiver's pose: the place it looks at, ``frontal``
#: when it looks at the robot.
SIS_POSES: tuple[str, ...] = ("frontal",) + OBJECT_PLACES

#: the colour names perception gives a salient object, with the HSI hue range (degrees,
#: start inclusive) each covers when saturated.
HUES: dict[str, tuple[float, float]] = {
    "red": (340.0, 14.0),
    "orange": (14.0, 40.0),
    "yellow": (40.0, 70.0),
    "green": (70.0, 170.0),
    "blue": (170.0, 260.0),
    "purple": (260.0, 340.0),
}
#: the colour names perception gives a salient object.
COLOURS: tuple[str, ...] = tuple(HUES)
#: the colour of each fruit of experiment 2.
FRUIT_COLOURS: dict[str, str] = {"apple": "red", "orange": "orange", "lemon": "yellow",
                                 "lime": "green"}


class _Any:
    """An argument that may be any term (a word heard, a colour chosen by the user)."""

    def __repr__(self) -> str:
        return "ANY"


#: in a percept pattern, an argument that may be anything.
ANY: Any = _Any()

# A percept pattern is a tuple (name, arg, ...) like a term; an argument is a constant (str),
# a tuple of constants (one of them) or ANY.
Pattern = tuple


@dataclass(frozen=True)
class Vocabulary:
    """The percepts a world can produce.

    Attributes:
        name: the world's name (``sis``, ``episodes``, ``fruits``).
        description: one line for listings.
        patterns: percept patterns: ``("pose", "face", ("frontal", "left"))`` stands for
            ``pose(face, frontal)`` and ``pose(face, left)``; :data:`ANY` for any argument.
    """

    name: str
    description: str
    patterns: tuple[Pattern, ...]

    def terms(self) -> list[tuple]:
        """Every percept as a term tuple, one per choice of the constants; :data:`ANY`
        arguments stay :data:`ANY` (a variable on the Prolog side)."""
        out: list[tuple] = []
        for pattern in self.patterns:
            choices = [arg if isinstance(arg, tuple) else (arg,) for arg in pattern[1:]]
            out += [(pattern[0], *args) for args in product(*choices)]
        return out

    def allows(self, percept: Any) -> bool:
        """True when ``percept`` (a term tuple or an atom) is one this world produces."""
        if isinstance(percept, str):
            percept = (percept,)
        if not isinstance(percept, tuple) or not percept:
            return False
        return any(_matches(percept, p) for p in self.patterns)

    def lines(self) -> Iterator[str]:
        """The patterns as Prolog-like text, one a line (``pose(face, frontal|left|...)``)."""
        for p in self.patterns:
            args = ["_" if a is ANY else "|".join(a) if isinstance(a, tuple) else a
                    for a in p[1:]]
            yield f"{p[0]}({', '.join(args)})" if args else p[0]


def _matches(percept: tuple, pattern: Pattern) -> bool:
    if percept[0] != pattern[0] or len(percept) != len(pattern):
        return False
    for value, arg in zip(percept[1:], pattern[1:], strict=True):
        if arg is ANY:
            continue
        if isinstance(arg, tuple) and value not in arg:
            return False
        if isinstance(arg, str) and value != arg:
            return False
    return True


def sis_vocabulary(places: Sequence[str] = PLACES, *, name: str = "sis",
                   description: str = "the Social Interactive Simulator (experiment 1)"
                   ) -> Vocabulary:
    """The simulator's percepts for these places (the first is the caregiver's face).

    The caregiver's gaze is perceived as the place it looks at (``pose(face, left)``), with
    ``frontal`` when it looks at the robot; toys are perceived with their place and a colour
    of the caregiver's choosing.
    """
    places = tuple(places)
    objects = places[1:]
    return Vocabulary(name, description, (
        ("see", ("face", "toy", "environment")),
        ("pose", "face", ("frontal",) + objects),
        ("at", "toy", objects),
        ("colour", "toy", ANY),
        ("at", places),
        ("hear", "attention"),
    ))


def episodes_vocabulary(colours: Sequence[str] = COLOURS, *, name: str = "episodes",
                        description: str = "episode scripts and the camera (head-pose classes)"
                        ) -> Vocabulary:
    """The percepts of the episode world and of perception on camera frames.

    The caregiver's gaze is perceived as a head-pose class (:data:`POSES`); an object in view
    by its colour and place; ``hear(Word)`` for attention and any word said.
    """
    return Vocabulary(name, description, (
        ("see", ("face", "object", "environment")),
        ("pose", "face", POSES),
        ("colour", "object", tuple(colours)),
        ("at", "object", PLACES),
        ("at", PLACES),
        ("hear", ANY),
    ))


#: the worlds by name.
WORLDS: dict[str, Vocabulary] = {
    "sis": sis_vocabulary(),
    "episodes": episodes_vocabulary(),
    "fruits": episodes_vocabulary(
        tuple(dict.fromkeys(FRUIT_COLOURS.values())), name="fruits",
        description="experiment 2: the episode world with fruits (fruit colours only)"),
}


def world(name: str) -> Vocabulary:
    """The vocabulary of the world called ``name``.

    Raises:
        ValueError: no such world; the message names the known ones.
    """
    try:
        return WORLDS[name]
    except KeyError:
        close = difflib.get_close_matches(name, list(WORLDS), n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ValueError(f"unknown world {name!r}{hint} (worlds: {', '.join(WORLDS)})") from None
