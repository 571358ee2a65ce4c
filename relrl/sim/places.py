"""The geometry of the Social Interactive Simulator: six places and the angles between them.

The robot and the caregiver sit face to face, 50 cm apart (da Silva & Romero 2012, section
5.1). Positions are in centimetres in the robot's frame: origin between the robot's eyes,
``x`` forward (towards the caregiver), ``y`` to the robot's left, ``z`` up. Place names are
the robot's: ``left`` is on the robot's left (the caregiver's right).

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
"""

from __future__ import annotations

import math

from perception.vocabulary import OBJECT_PLACES, PLACES

__all__ = [
    "ANGLE_BETWEEN",
    "CAREGIVER_PAN_TILT",
    "CENTRE",
    "DISTANCE_CM",
    "PLACES",
    "POSITIONS",
    "ROBOT_PAN_TILT",
    "TOY_PLACES",
    "place_index",
]

# PLACES (the robot's view; index 0 is the caregiver's face) come from the shared vocabulary.
#: the places a toy can be put at (every place but the caregiver).
TOY_PLACES: tuple[str, ...] = OBJECT_PLACES
#: index of ``centre`` in :data:`PLACES`.
CENTRE = 0
#: distance between the robot's and the caregiver's eyes, in centimetres.
DISTANCE_CM = 50.0

#: place -> (x, y, z) in centimetres, robot frame (see the module documentation).
POSITIONS: dict[str, tuple[float, float, float]] = {
    "centre": (DISTANCE_CM, 0.0, 0.0),
    "left": (25.0, 40.0, -10.0),
    "left_down": (25.0, 20.0, -25.0),
    "down": (25.0, 0.0, -25.0),
    "right_down": (25.0, -20.0, -25.0),
    "right": (25.0, -40.0, -10.0),
}

_INDEX = {name: i for i, name in enumerate(PLACES)}


def place_index(name: str) -> int:
    """Return the index of a place name in :data:`PLACES`.

    Raises:
        KeyError: ``name`` is not a place.
    """
    return _INDEX[name]


def _direction(frm: tuple[float, float, float], to: tuple[float, float, float]
               ) -> tuple[float, float, float]:
    d = tuple(b - a for a, b in zip(frm, to, strict=True))
    n = math.sqrt(sum(c * c for c in d))
    return d[0] / n, d[1] / n, d[2] / n


def _pan_tilt(forward: float, lateral: float, up: float) -> tuple[float, float]:
    pan = math.degrees(math.atan2(lateral, forward))
    tilt = math.degrees(math.atan2(up, math.hypot(forward, lateral)))
    return round(pan, 1), round(tilt, 1)


def _robot_pan_tilt(place: str) -> tuple[float, float]:
    x, y, z = POSITIONS[place]
    return _pan_tilt(x, y, z)


def _caregiver_pan_tilt(place: str) -> tuple[float, float]:
    if place == "centre":
        return 0.0, 0.0  # the caregiver's centre is the robot's face
    x, y, z = POSITIONS[place]
    return _pan_tilt(DISTANCE_CM - x, y, z)  # the caregiver faces -x


#: place -> (pan, tilt) in degrees the robot's head turns to look at it.
ROBOT_PAN_TILT: dict[str, tuple[float, float]] = {p: _robot_pan_tilt(p) for p in PLACES}
#: place -> (pan, tilt) in degrees the caregiver's head turns to look at it.
CAREGIVER_PAN_TILT: dict[str, tuple[float, float]] = {p: _caregiver_pan_tilt(p) for p in PLACES}

_DIRS = [_direction((0.0, 0.0, 0.0), POSITIONS[p]) for p in PLACES]

#: ANGLE_BETWEEN[i][j]: the angle in degrees, seen from the robot's eyes, between places i and
#: j (indices of :data:`PLACES`) — how far the robot's head turns to go from one to the other.
ANGLE_BETWEEN: tuple[tuple[float, ...], ...] = tuple(
    tuple(round(math.degrees(math.acos(max(-1.0, min(1.0, sum(a * b for a, b in
                                                              zip(u, v, strict=True)))))), 1)
          for v in _DIRS)
    for u in _DIRS
)
