"""Motor scripts: each response of a domain maps to a sequence of servo poses with timing.

Scripts are data, declared in the calibration TOML (or a scripts TOML next to it)::

    [scripts."look(left)"]
    doc = "turn the gaze to the left region"
    steps = [{ direction = "left" }]

    [scripts.name_object]
    doc = "declarative pointing: a small nod towards the object while the robot speaks"
    steps = [
      { offset = { neck_tilt = -60 }, speed = 400, hold_ms = 150 },
      { offset = {}, speed = 400, hold_ms = 100 },
    ]

A step has exactly one target — ``direction`` (a direction of the calibration), ``pose``
(absolute pulse widths of some servos, in microseconds) or ``offset`` (microseconds added to
the pose the head had when the script started; ``{}`` returns there) — and optionally
``speed`` (microseconds per second, never faster than the calibrated speed of a servo) and
``hold_ms`` (a pause after the move ends). Every target is clamped to the calibrated range
when played, so no script can drive a servo past its limits.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

__all__ = ["MotorScript", "Step", "normalise_response", "parse_scripts"]

#: the longest pause a step may hold, in milliseconds.
MAX_HOLD_MS = 60_000
_TARGETS = ("direction", "pose", "offset")
_STEP_KEYS = frozenset(_TARGETS + ("speed", "hold_ms"))


@dataclass(frozen=True)
class Step:
    """One step of a motor script.

    Attributes:
        kind: ``"direction"``, ``"pose"`` or ``"offset"``.
        direction: the direction name when ``kind == "direction"``.
        values: servo name -> microseconds (absolute for a pose, relative for an offset).
        speed: optional speed limit in microseconds per second.
        hold_ms: pause after the move ends, in milliseconds.
    """

    kind: str
    direction: str | None = None
    values: Mapping[str, float] = field(default_factory=dict)
    speed: float | None = None
    hold_ms: int = 0

    def to_toml_inline(self) -> dict[str, Any]:
        """The step as a plain mapping, the shape it has in TOML."""
        out: dict[str, Any] = {}
        if self.kind == "direction":
            out["direction"] = self.direction
        else:
            out[self.kind] = dict(self.values)
        if self.speed is not None:
            out["speed"] = self.speed
        if self.hold_ms:
            out["hold_ms"] = self.hold_ms
        return out


@dataclass(frozen=True)
class MotorScript:
    """A named sequence of steps played for one response."""

    response: str
    steps: tuple[Step, ...]
    doc: str = ""


def normalise_response(text: str) -> str:
    """Canonical text of a response term: whitespace outside quotes removed.

    ``"look( left_down )"`` and ``"look(left_down)"`` name the same response.
    """
    out: list[str] = []
    quote: str | None = None
    for ch in str(text).strip():
        if quote:
            out.append(ch)
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
            out.append(ch)
        elif not ch.isspace():
            out.append(ch)
    return "".join(out)


def _number(value: Any, where: str, fail) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        fail(where, f"{value!r} is not a number of microseconds")
    return float(value)


def _parse_step(raw: Any, where: str, servos: Mapping[str, Any],
                directions: Mapping[str, Any], fail) -> Step:
    if not isinstance(raw, Mapping):
        fail(where, f"a step must be a table like {{ direction = \"left\" }}, got {raw!r}")
    extra = sorted(set(raw) - _STEP_KEYS)
    if extra:
        fail(f"{where}.{extra[0]}", f"unknown step key; use one of {sorted(_STEP_KEYS)}")
    kinds = [k for k in _TARGETS if k in raw]
    if len(kinds) != 1:
        fail(where, "a step needs exactly one of direction, pose or offset")
    kind = kinds[0]
    speed = raw.get("speed")
    if speed is not None:
        speed = _number(speed, f"{where}.speed", fail)
        if speed <= 0:
            fail(f"{where}.speed", f"{speed:g} must be positive (microseconds per second)")
    hold = raw.get("hold_ms", 0)
    if isinstance(hold, bool) or not isinstance(hold, int) or not 0 <= hold <= MAX_HOLD_MS:
        fail(f"{where}.hold_ms", f"{hold!r} must be an integer in 0..{MAX_HOLD_MS}")
    if kind == "direction":
        name = raw["direction"]
        if name not in directions:
            fail(f"{where}.direction", f"{name!r} is not a direction; known: "
                 f"{', '.join(directions)}")
        return Step("direction", direction=name, speed=speed, hold_ms=hold)
    values = raw[kind]
    if not isinstance(values, Mapping):
        fail(f"{where}.{kind}", f"must be a table of servo = microseconds, got {values!r}")
    parsed: dict[str, float] = {}
    for servo, value in values.items():
        key = f"{where}.{kind}.{servo}"
        if servo not in servos:
            fail(key, f"unknown servo; known: {', '.join(servos)}")
        parsed[servo] = _number(value, key, fail)
        if kind == "pose":
            s = servos[servo]
            if not s.min <= parsed[servo] <= s.max:
                fail(key, f"{parsed[servo]:g} is outside the calibrated range {s.min}..{s.max}")
    return Step(kind, values=parsed, speed=speed, hold_ms=hold)


def parse_scripts(raw: Any, where: str, servos: Mapping[str, Any],
                  directions: Mapping[str, Any], fail) -> dict[str, MotorScript]:
    """Parse a ``[scripts]`` table.

    Args:
        raw: the table read from TOML (response text -> ``{doc, steps}``).
        where: the key prefix used in messages (``"scripts"``).
        servos: servo name -> servo (with ``min`` and ``max``) of the calibration.
        directions: direction name -> pose of the calibration.
        fail: ``fail(key, message)`` raises the calibration error naming file and key.

    Returns:
        Normalised response text -> script.
    """
    if not isinstance(raw, Mapping):
        fail(where, "must be a table of response = { steps = [...] }")
    scripts: dict[str, MotorScript] = {}
    for response, body in raw.items():
        key = f'{where}."{response}"'
        name = normalise_response(response)
        if not name:
            fail(key, "a response name cannot be empty")
        if name in scripts:
            fail(key, f"duplicate script for response {name!r}")
        if not isinstance(body, Mapping) or "steps" not in body:
            fail(key, "a script must be a table with steps = [ ... ]")
        extra = sorted(set(body) - {"steps", "doc"})
        if extra:
            fail(f"{key}.{extra[0]}", "unknown script key; use steps and doc")
        steps = body["steps"]
        if not isinstance(steps, list) or not steps:
            fail(f"{key}.steps", "must be a non-empty list of steps")
        doc = body.get("doc", "")
        if not isinstance(doc, str):
            fail(f"{key}.doc", f"{doc!r} must be a string")
        scripts[name] = MotorScript(
            name,
            tuple(_parse_step(s, f"{key}.steps[{i}]", servos, directions, fail)
                  for i, s in enumerate(steps)),
            doc)
    return scripts
