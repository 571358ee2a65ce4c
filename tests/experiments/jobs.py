"""Small job functions for the runner's tests (importable by spawned worker processes)."""

from __future__ import annotations

import os
import time

from relrl.errors import ConfigError


def square(x: int, *, report) -> dict:
    for point in range(3):
        report({"kind": "point", "point": point, "x": x})
    return {"x": x, "square": x * x, "pid": os.getpid()}


def bad_value(x: int, *, report) -> dict:
    raise ConfigError(f"x={x}: not a good value")


def bug(x: int, *, report) -> dict:
    return {"x": [1, 2][x]}          # IndexError for x >= 2


def vanish(x: int, *, report) -> dict:
    os._exit(3)


def slow(x: int, *, report) -> dict:
    for point in range(1000):
        time.sleep(0.05)
        report({"kind": "point", "point": point})
    return {"x": x}


def square_or_fail(x: int, *, report) -> dict:
    if x == 2:
        raise ConfigError(f"x={x}: not a good value")
    return square(x, report=report)
