"""The words perception shares with the knowledge layer, the simulator and the head.

Places, head-pose classes, gaze poses and fruit colours are the project's shared vocabulary
(:mod:`perception.vocabulary`, re-exported here); this module adds what only perception
needs: the hue range of each colour name.

Everything is in the **camera image's frame**, which is also the robot's frame: "left" is
the left of the image, i.e. the robot's left. ``left_1`` and ``left_2`` are faces turned so
that the nose points to the **left of the image** (the caregiver looks toward the robot's left,
the caregiver's own right): ``_1`` a slight turn (about 20-40 degrees of pan, still seen by the
frontal detector), ``_2`` a strong turn (profile, about 60-90 degrees). ``right_*`` mirror them;
``down`` is a face pitched down toward the table.
"""

from __future__ import annotations

from perception.vocabulary import COLOURS as COLOUR_NAMES
from perception.vocabulary import FRUIT_COLOURS, GAZE_POSE, OBJECT_PLACES, PLACES, POSES

__all__ = ["COLOURS", "FRUIT_COLOURS", "GAZE_POSE", "OBJECT_PLACES", "PLACES", "POSES"]

#: colour names, with the HSI hue range (degrees, start inclusive) each covers when saturated.
COLOURS: dict[str, tuple[float, float]] = {
    "red": (340.0, 14.0),
    "orange": (14.0, 40.0),
    "yellow": (40.0, 70.0),
    "green": (70.0, 170.0),
    "blue": (170.0, 260.0),
    "purple": (260.0, 340.0),
}
assert tuple(COLOURS) == COLOUR_NAMES, "a hue range for every colour name of percepts"
