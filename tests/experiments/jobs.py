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


def learned_again(x: int, *, report) -> dict:
    """Three points, a check that restarts, two more points (a restart has no initial
    evaluation), a check that keeps it."""
    for point in range(3):
        report({"kind": "point", "point": point})
    report({"kind": "check", "entry": {"attempt": 0, "restart": True}})
    for point in range(3, 5):
        report({"kind": "point", "point": point})
    report({"kind": "check", "entry": {"attempt": 1, "restart": False}})
    return {"x": x}
