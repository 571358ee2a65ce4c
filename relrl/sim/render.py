"""Drawing the simulator: a text line-up and a small top-view RGB image, from one record.

Both read a :class:`~relrl.sim.metrics.StepRecord` only, so any trace (live or saved) can be
drawn. numpy is the only dependency.
"""

from __future__ import annotations

import numpy as np

from relrl.sim.errors import SimError
from relrl.sim.metrics import StepRecord
from relrl.sim.places import DISTANCE_CM, TOY_PLACES, Layout, layout

__all__ = ["IMAGE_SHAPE", "render_rgb", "render_text"]

_SCALE = 3.0  # pixels per centimetre
_X_MAX, _X_MIN = DISTANCE_CM + 12.0, -12.0  # forward range (cm), top to bottom of the image
_Y_HALF = 50.0  # lateral half-width (cm)
#: (height, width, 3) of :func:`render_rgb` images.
IMAGE_SHAPE = (int((_X_MAX - _X_MIN) * _SCALE), int(2 * _Y_HALF * _SCALE), 3)

_COLOURS = {
    "red": (220, 40, 40), "green": (40, 170, 60), "blue": (50, 90, 220),
    "yellow": (235, 200, 30), "orange": (240, 140, 20), "purple": (140, 60, 170),
    "": (120, 120, 120),
}
_OTHER_TOY = (150, 80, 160)
_BACKGROUND = (245, 245, 240)
_TABLE = (222, 205, 170)
_SKIN = (235, 190, 150)
_ROBOT = (140, 150, 165)
_CAREGIVER_GAZE = (40, 80, 200)
_ROBOT_GAZE = (230, 120, 0)
_ATTENTION = (250, 200, 0)


def _pixel(place_or_xy: str | tuple[float, float], positions: dict[str, tuple[float, ...]]
           ) -> tuple[float, float]:
    x, y = positions[place_or_xy][:2] if isinstance(place_or_xy, str) else place_or_xy
    return (_X_MAX - x) * _SCALE, (_Y_HALF - y) * _SCALE  # robot's left on the image's left


def _disc(img: np.ndarray, centre: tuple[float, float], radius: float,
          colour: tuple[int, int, int]) -> None:
    rows, cols = np.ogrid[:img.shape[0], :img.shape[1]]
    mask = (rows - centre[0]) ** 2 + (cols - centre[1]) ** 2 <= radius ** 2
    img[mask] = colour


def _ring(img: np.ndarray, centre: tuple[float, float], radius: float, width: float,
          colour: tuple[int, int, int]) -> None:
    rows, cols = np.ogrid[:img.shape[0], :img.shape[1]]
    d2 = (rows - centre[0]) ** 2 + (cols - centre[1]) ** 2
    img[(d2 <= (radius + width) ** 2) & (d2 >= radius ** 2)] = colour


def _line(img: np.ndarray, a: tuple[float, float], b: tuple[float, float],
          colour: tuple[int, int, int]) -> None:
    n = int(max(abs(b[0] - a[0]), abs(b[1] - a[1]))) + 1
    rows = np.linspace(a[0], b[0], n)
    cols = np.linspace(a[1], b[1], n)
    for dr, dc in ((0, 0), (1, 0), (0, 1)):  # two pixels thick
        r = np.clip(np.rint(rows).astype(int) + dr, 0, img.shape[0] - 1)
        c = np.clip(np.rint(cols).astype(int) + dc, 0, img.shape[1] - 1)
        img[r, c] = colour


def render_rgb(rec: StepRecord, where: Layout | None = None) -> np.ndarray:
    """Draw a record as a top view: caregiver above, robot below, toys on the table.

    The blue line is the caregiver's gaze, the orange one the robot's; a yellow ring around
    the caregiver marks attention. ``where`` is the world's layout (default: the paper's five
    places). Returns a ``uint8`` array of shape :data:`IMAGE_SHAPE`.
    """
    if where is None:
        where = layout(5)
    pos = where.positions
    if any(p not in pos for p in (rec.focus, *(t for t, _ in rec.toys))):
        raise SimError(f"cannot draw places outside the layout's {len(where.toy_places)}: "
                       f"pass the world's layout to render_rgb")
    img = np.empty(IMAGE_SHAPE, dtype=np.uint8)
    img[:] = _BACKGROUND
    first, last = where.toy_places[0], where.toy_places[-1]
    top, left = _pixel((pos[first][0] + 12.0, pos[first][1] + 8.0), pos)
    bottom, right = _pixel((25.0 - 12.0, pos[last][1] - 8.0), pos)
    img[int(top):int(bottom), int(left):int(right)] = _TABLE
    caregiver, robot = _pixel("centre", pos), _pixel((0.0, 0.0), pos)
    radius = min(9.0, 45.0 / max(5, len(where.toy_places)) * 5)
    for place in where.toy_places:
        _disc(img, _pixel(place, pos), 2.0, (170, 150, 120))
    toys = dict(rec.toys)
    for place, colour in toys.items():
        centre = _pixel(place, pos)
        _disc(img, centre, radius, _COLOURS.get(colour, _OTHER_TOY))
        if place == rec.target:
            _ring(img, centre, radius + 1.0, 2.0, (30, 30, 30))
    gaze_to = robot if rec.gaze == "frontal" else _pixel(rec.gaze, pos)
    _line(img, caregiver, gaze_to, _CAREGIVER_GAZE)
    _line(img, robot, _pixel(rec.focus, pos), _ROBOT_GAZE)
    if rec.attention:
        _ring(img, caregiver, 18.0, 4.0, _ATTENTION)
    _disc(img, caregiver, 16.0, _SKIN)
    _disc(img, robot, 16.0, _ROBOT)
    return img


def render_text(rec: StepRecord, places: tuple[str, ...] = TOY_PLACES) -> str:
    """Describe a record in a few lines of text (the ``ansi`` render mode); ``places`` are
    the world's toy places (default: the paper's five)."""
    cells = []
    for place in places:
        colour = dict(rec.toys).get(place)
        mark = "." if colour is None else (colour or "toy")
        if place == rec.target:
            mark += "*"
        if place == rec.gaze:
            mark = "<" + mark + ">"
        if place == rec.focus:
            mark = "[" + mark + "]"
        cells.append(f"{mark:^12}")
    looks = "the robot (frontal)" if rec.gaze == "frontal" else rec.gaze
    face = "[caregiver]" if rec.focus == "centre" else "caregiver"
    lines = [
        f"t={rec.t} phase={rec.phase} opportunity={rec.opportunity} trial={rec.trial}"
        + ("  EYE CONTACT" if rec.contact else "") + ("  ATTENTION" if rec.attention else ""),
        f"{face:^60}",
        f"{'caregiver looks at ' + looks:^60}",
        "".join(f"{p:^12}" for p in places),
        "".join(cells),
        f"{'robot looks at ' + rec.focus:^60}",
    ]
    return "\n".join(lines) + "\n"
