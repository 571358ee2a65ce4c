"""The geometry of the Social Interactive Simulator: places on a table and the angles between them.

The robot and the caregiver sit face to face, 50 cm apart (da Silva & Romero 2012, section
5.1). Positions are in centimetres in the robot's frame: origin between the robot's eyes,
``x`` forward (towards the caregiver), ``y`` to the robot's left, ``z`` up. Place names are
the robot's: ``left`` is on the robot's left (the caregiver's right).

The paper's world has five toy places (:func:`layout` with ``5``, the module's constants):

=============  ====================  =========  =========  ============  ============
place          position (x, y, z)    robot pan  robot tilt caregiver pan caregiver tilt
=============  ====================  =========  =========  ============  ============
``centre``     (50, 0, 0)            0.0        0.0        (the robot)   (the robot)
``left``       (25, 40, -10)         58.0       -12.0      58.0          -12.0
``left_down``  (25, 20, -25)         38.7       -38.0      38.7          -38.0
``down``       (25, 0, -25)          0.0        -45.0      0.0           -45.0
``right_down`` (25, -20, -25)        -38.7      -38.0      -38.7         -38.0
``right``      (25, -40, -10)        -58.0      -12.0      -58.0         -12.0
=============  ====================  =========  =========  ============  ============

``centre`` is the caregiver's face (for the robot) and the robot's face (for the caregiver):
0 degrees means the two look at each other. The toy places are half-way between them on a
table 25 cm below eye level (``left``/``right`` higher, at the table's far corners), so both
see every place within +-90 degrees of pan. Pan is positive towards the robot's left; the
caregiver's pan is given in the same sense (towards the robot's left) for comparison. Tilt is
negative downwards.

**Growing worlds.** :func:`layout` with ``P`` toy places puts them at equal steps along the
same table edge (the polyline ``left - left_down - down - right_down - right``): ``P = 9``
adds the midpoints, ``17`` and ``33`` subdivide again, so every world spans the same field
and a place of a small world is a place of the larger ones (``P = 2^k + 1``). Names for
``P != 5`` come from :func:`place_names`: ``left_m ... left_1, down, right_1 ... right_m``
from the robot's left to its right (no ``down`` when ``P`` is even).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

from perception.vocabulary import OBJECT_PLACES
from perception.vocabulary import PLACES as _VOCABULARY_PLACES

__all__ = [
    "ANGLE_BETWEEN",
    "CAREGIVER_PAN_TILT",
    "CENTRE",
    "DISTANCE_CM",
    "MAX_PLACES",
    "PLACES",
    "POSITIONS",
    "ROBOT_PAN_TILT",
    "TOY_PLACES",
    "Layout",
    "layout",
    "place_index",
    "place_names",
]

#: index of ``centre`` (the caregiver's face) in every layout's places.
CENTRE = 0
#: distance between the robot's and the caregiver's eyes, in centimetres.
DISTANCE_CM = 50.0
#: the most toy places a world may have.
MAX_PLACES = 257

#: the paper's five toy places come from the project's shared vocabulary.
_PAPER_NAMES: tuple[str, ...] = OBJECT_PLACES
_EDGE = ((25.0, 40.0, -10.0), (25.0, 20.0, -25.0), (25.0, 0.0, -25.0), (25.0, -20.0, -25.0),
         (25.0, -40.0, -10.0))


def place_names(n: int) -> tuple[str, ...]:
    """The names of ``n`` toy places, from the robot's left to its right.

    ``5`` gives the paper's names (``left, left_down, down, right_down, right``); any other
    number ``left_m ... left_1, down, right_1 ... right_m`` (``down`` only when ``n`` is odd).

    Raises:
        ValueError: ``n`` is not a whole number from 2 to :data:`MAX_PLACES`.
    """
    if not isinstance(n, int) or isinstance(n, bool) or not 2 <= n <= MAX_PLACES:
        raise ValueError(f"places={n!r}: use a whole number from 2 to {MAX_PLACES}")
    if n == 5:
        return _PAPER_NAMES
    m = n // 2
    middle = ("down",) if n % 2 else ()
    return (tuple(f"left_{k}" for k in range(m, 0, -1)) + middle
            + tuple(f"right_{k}" for k in range(1, m + 1)))


def _edge_point(s: float) -> tuple[float, float, float]:
    """The point at parameter ``s`` in [0, 4] along the table edge (vertex k at s = k)."""
    k = min(int(s), len(_EDGE) - 2)
    f = s - k
    a, b = _EDGE[k], _EDGE[k + 1]
    return tuple(round(x + f * (y - x), 6) for x, y in zip(a, b, strict=True))  # type: ignore


def _direction(frm: tuple[float, float, float], to: tuple[float, float, float]
               ) -> tuple[float, float, float]:
    d = tuple(b - a for a, b in zip(frm, to, strict=True))
    n = math.sqrt(sum(c * c for c in d))
    return d[0] / n, d[1] / n, d[2] / n


def _pan_tilt(forward: float, lateral: float, up: float) -> tuple[float, float]:
    pan = math.degrees(math.atan2(lateral, forward))
    tilt = math.degrees(math.atan2(up, math.hypot(forward, lateral)))
    return round(pan, 1), round(tilt, 1)


@dataclass(frozen=True)
class Layout:
    """The places of one world and the angles between them.

    Attributes:
        places: every place, ``centre`` (the caregiver's face) first, then the toy places
            from the robot's left to its right.
        toy_places: the places a toy can be put at (every place but ``centre``).
        positions: place -> (x, y, z) in centimetres, robot frame.
        robot_pan_tilt: place -> (pan, tilt) in degrees the robot's head turns to look at it.
        caregiver_pan_tilt: place -> (pan, tilt) the caregiver's head turns to look at it.
        angle_between: ``angle_between[i][j]``, the angle in degrees seen from the robot's
            eyes between places ``i`` and ``j`` (indices of ``places``): how far the robot's
            head turns to go from one to the other.
    """

    places: tuple[str, ...]
    toy_places: tuple[str, ...]
    positions: dict[str, tuple[float, float, float]]
    robot_pan_tilt: dict[str, tuple[float, float]]
    caregiver_pan_tilt: dict[str, tuple[float, float]]
    angle_between: tuple[tuple[float, ...], ...]

    def index(self, name: str) -> int:
        """The index of a place name in :attr:`places`.

        Raises:
            KeyError: ``name`` is not a place of this layout.
        """
        return _index(self.places)[name]


@lru_cache(maxsize=None)
def _index(places: tuple[str, ...]) -> dict[str, int]:
    return {name: i for i, name in enumerate(places)}


@lru_cache(maxsize=None)
def layout(n: int = 5) -> Layout:
    """The layout of a world with ``n`` toy places (see the module documentation)."""
    toy = place_names(n)
    places = ("centre",) + toy
    positions = {"centre": (DISTANCE_CM, 0.0, 0.0)}
    for k, name in enumerate(toy):
        positions[name] = _edge_point(4.0 * k / (n - 1))
    robot = {p: _pan_tilt(*positions[p]) for p in places}
    caregiver = {"centre": (0.0, 0.0)}  # the caregiver's centre is the robot's face
    for p in toy:
        x, y, z = positions[p]
        caregiver[p] = _pan_tilt(DISTANCE_CM - x, y, z)  # the caregiver faces -x
    dirs = [_direction((0.0, 0.0, 0.0), positions[p]) for p in places]
    angles = tuple(
        tuple(round(math.degrees(math.acos(max(-1.0, min(1.0, sum(
            a * b for a, b in zip(u, v, strict=True)))))), 1) for v in dirs)
        for u in dirs)
    return Layout(places, toy, positions, robot, caregiver, angles)


_PAPER = layout(5)
assert _PAPER.places == _VOCABULARY_PLACES and _PAPER.toy_places == OBJECT_PLACES
#: the places of the paper's world, robot's view; index 0 is the caregiver's face (the one
#: definition, :mod:`perception.vocabulary`, which ``layout(5)`` reproduces).
PLACES: tuple[str, ...] = _VOCABULARY_PLACES
#: the places a toy can be put at (every place but the caregiver).
TOY_PLACES: tuple[str, ...] = OBJECT_PLACES
#: place -> (x, y, z) in centimetres, robot frame (see the module documentation).
POSITIONS: dict[str, tuple[float, float, float]] = _PAPER.positions
#: place -> (pan, tilt) in degrees the robot's head turns to look at it.
ROBOT_PAN_TILT: dict[str, tuple[float, float]] = _PAPER.robot_pan_tilt
#: place -> (pan, tilt) in degrees the caregiver's head turns to look at it.
CAREGIVER_PAN_TILT: dict[str, tuple[float, float]] = _PAPER.caregiver_pan_tilt
#: ANGLE_BETWEEN[i][j]: the angle in degrees, seen from the robot's eyes, between places i and
#: j (indices of :data:`PLACES`) — how far the robot's head turns to go from one to the other.
ANGLE_BETWEEN: tuple[tuple[float, ...], ...] = _PAPER.angle_between


def place_index(name: str) -> int:
    """Return the index of a place name in :data:`PLACES` (the paper's world).

    Raises:
        KeyError: ``name`` is not a place.
    """
    return _PAPER.index(name)
