"""Shared fixtures for the head tests: a fast calibration and fake controllers."""

from __future__ import annotations

from pathlib import Path

import pytest

from head.calibration import load_calibration

#: a five-servo head whose servos move fast, so real-time serial tests take milliseconds.
FAST_TOML = """
[head]
name = "fast test head"
tolerance_us = 10

[servos.neck_pan]
channel = 0
min = 1000
centre = 1500
max = 2000
speed = 10000

[servos.neck_tilt]
channel = 1
min = 1200
centre = 1500
max = 1800
speed = 8000

[servos.eye_pan]
channel = 2
min = 1300
centre = 1500
max = 1700
speed = 10000

[servos.eye_tilt]
channel = 3
min = 1350
centre = 1500
max = 1650
speed = 10000

[servos.mouth]
channel = 5
min = 1400
centre = 1500
max = 1700
speed = 10000

[directions]
centre = {}
left = { neck_pan = 1900, eye_pan = 1600 }
left_down = { neck_pan = 1800, neck_tilt = 1300, eye_tilt = 1400 }
down = { neck_tilt = 1250 }
right_down = { neck_pan = 1200, neck_tilt = 1300, eye_tilt = 1400 }
right = { neck_pan = 1100, eye_pan = 1400 }

[scripts."look(left)"]
steps = [{ direction = "left" }]

[scripts."look(down)"]
steps = [{ direction = "down" }]

[scripts.name_object]
steps = [
  { offset = { neck_tilt = -50, mouth = 100 }, hold_ms = 20 },
  { offset = {} },
]
"""


@pytest.fixture
def fast_toml() -> str:
    """The text of the fast calibration."""
    return FAST_TOML


@pytest.fixture
def fast_path(tmp_path: Path) -> Path:
    """A calibration file with fast servos."""
    path = tmp_path / "fast.toml"
    path.write_text(FAST_TOML)
    return path


@pytest.fixture
def fast_cal(fast_path: Path):
    """The fast calibration, loaded."""
    return load_calibration(fast_path)
