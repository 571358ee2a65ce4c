"""The words perception shares with the knowledge layer and the simulator.

Everything here is in the **camera image's frame**, which is also the robot's frame: "left" is
the left of the image, i.e. the robot's left.

* :data:`PLACES` are where the head can look. ``centre`` is the caregiver's face; the other five
  are the regions of the paper's experiment 2 where a fruit or toy can appear.
* :data:`POSES` are the coarse head-pose classes of experiment 2. ``left_1`` and ``left_2`` are
  faces turned so that the nose points to the **left of the image** (the caregiver looks toward
  the robot's left, which is the caregiver's own right): ``_1`` a slight turn (about 20-40
  degrees of pan, still seen by the frontal detector), ``_2`` a strong turn (profile, about
  60-90 degrees). ``right_*`` mirror them. ``down`` is a face pitched down toward the table.
* :data:`GAZE_POSE` is the pose a caregiver shows while looking at each place; the simulator
  uses it to draw the caregiver and a learner can use it to follow the gaze.
* :data:`COLOURS` are the colour names the colour stage gives the salient object.
"""

from __future__ import annotations

__all__ = ["COLOURS", "FRUIT_COLOURS", "GAZE_POSE", "PLACES", "POSES"]

#: where the head can look; ``centre`` is the caregiver's face.
PLACES: tuple[str, ...] = ("left", "left_down", "down", "right_down", "right", "centre")

#: the six head-pose classes (see the module docstring for which side is which).
POSES: tuple[str, ...] = ("frontal", "left_1", "left_2", "right_1", "right_2", "down")

#: the pose a caregiver shows while looking at a place.
GAZE_POSE: dict[str, str] = {
    "centre": "frontal",
    "left": "left_2",
    "left_down": "left_1",
    "down": "down",
    "right_down": "right_1",
    "right": "right_2",
}

#: colour names, with the HSI hue range (degrees, start inclusive) each covers when saturated.
COLOURS: dict[str, tuple[float, float]] = {
    "red": (340.0, 14.0),
    "orange": (14.0, 40.0),
    "yellow": (40.0, 70.0),
    "green": (70.0, 170.0),
    "blue": (170.0, 260.0),
    "purple": (260.0, 340.0),
}

#: the colour of each fruit of experiment 2.
FRUIT_COLOURS: dict[str, str] = {"apple": "red", "orange": "orange", "lemon": "yellow",
                                 "lime": "green"}
