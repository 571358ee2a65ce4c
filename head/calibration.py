"""Calibration of a head as data: servos, limits, speeds, direction poses and motor scripts.

A calibration is one TOML file (see ``examples/heads/wha8030.toml``)::

    [head]
    name = "Dr Robot WHA8030"
    protocol = "pms5005"        # default protocol (``--protocol`` overrides it)
    tolerance_us = 20           # how close a servo must be to count as at a pose
    scripts = "more.toml"       # optional: more scripts from a file next to this one

    [servos.neck_pan]
    channel = 0
    min = 1000                  # pulse widths in microseconds
    centre = 1500
    max = 2000
    speed = 500                 # microseconds per second (the fastest this servo may move)

    [directions]
    left = { neck_pan = 1800 }  # servos left out stay at their centre

    [scripts."look(left)"]
    steps = [{ direction = "left" }]

Everything is checked on load; a problem is one line naming the file and the key. The
:meth:`Calibration.clamp` method is the one place where commanded pulses are limited to the
calibrated range: every head calls it before any byte is written.
"""

from __future__ import annotations

import math
import os
import re
import tempfile
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from importlib.resources import files
from pathlib import Path
from typing import Any, NoReturn

from head.errors import CalibrationError, UnknownDirection, UnknownResponse, UnknownServo
from head.scripts import MotorScript, normalise_response, parse_scripts
from head.tomlfile import MAX_NESTING, read_limited, too_deep
from perception.vocabulary import PLACES

__all__ = [
    "DEFAULT_CALIBRATION",
    "DIRECTIONS",
    "PULSE_RANGE",
    "Calibration",
    "Servo",
    "dump_calibration",
    "load_calibration",
    "save_calibration",
]

#: the six directions of the paper's head (the shared vocabulary's places); ``centre`` looks
#: forward, at the caregiver.
DIRECTIONS: tuple[str, ...] = PLACES
#: the absolute range of pulse widths any hobby servo accepts, in microseconds.
PULSE_RANGE: tuple[int, int] = (500, 2500)
#: the fastest a servo may be calibrated to move, in microseconds per second.
MAX_SPEED = 20_000.0
#: the slowest speed, microseconds per second (one unit of the Maestro's speed setting).
MIN_SPEED = 25.0
#: the calibration used when none is given: package data of ``head`` (in the source tree
#: ``head/calibrations`` links to ``examples/heads``).
DEFAULT_CALIBRATION = Path(str(files("head") / "calibrations" / "wha8030.toml"))

_NAME = re.compile(r"^[a-z][a-z0-9_]*$")
_HEAD_KEYS = frozenset({"name", "protocol", "baudrate", "tolerance_us", "scripts"})
_SERVO_KEYS = frozenset({"channel", "min", "centre", "max", "speed", "acceleration"})
_TOP_KEYS = frozenset({"head", "servos", "directions", "scripts"})


@dataclass(frozen=True)
class Servo:
    """One calibrated servo.

    Attributes:
        name: the servo's name (``neck_pan``).
        channel: the controller channel it is plugged into.
        min, centre, max: pulse widths in microseconds, ``min < centre < max``.
        speed: the fastest it may move, microseconds per second.
        acceleration: optional controller acceleration setting (0 = controller default).
    """

    name: str
    channel: int
    min: int
    centre: int
    max: int
    speed: float
    acceleration: int = 0

    def clamp(self, value: float) -> int:
        """Round ``value`` to a whole microsecond inside ``[min, max]``."""
        return int(min(self.max, max(self.min, round(value))))


@dataclass(frozen=True)
class Calibration:
    """A validated calibration: build it with :func:`load_calibration`.

    Attributes:
        servos: servo name -> servo, in file order.
        directions: direction name -> full pose (every servo named).
        scripts: normalised response text -> motor script.
        name: a label for the head.
        protocol: the default protocol name, or ``None``.
        baudrate: the serial speed, or ``None`` for the protocol's default.
        tolerance_us: how close every servo must be to a pose to count as at it.
        path: the file it was loaded from.
        scripts_file: the extra scripts file named in ``[head] scripts``, if any.
    """

    servos: dict[str, Servo]
    directions: dict[str, dict[str, int]]
    scripts: dict[str, MotorScript] = field(default_factory=dict)
    name: str = "head"
    protocol: str | None = None
    baudrate: int | None = None
    tolerance_us: int = 20
    path: Path | None = None
    scripts_file: str | None = None
    external_scripts: frozenset[str] = frozenset()

    def centre_pose(self) -> dict[str, int]:
        """Every servo at its calibrated centre."""
        return {name: s.centre for name, s in self.servos.items()}

    def pose_of(self, direction: str) -> dict[str, int]:
        """The full pose of a direction; :class:`UnknownDirection` names the known ones."""
        try:
            return dict(self.directions[direction])
        except KeyError:
            raise UnknownDirection(
                f"unknown direction {direction!r}; use one of {', '.join(self.directions)}"
            ) from None

    def script_for(self, response: str) -> MotorScript:
        """The motor script of a response; :class:`UnknownResponse` lists the known ones."""
        key = normalise_response(response)
        try:
            return self.scripts[key]
        except KeyError:
            raise UnknownResponse(
                f"no motor script for response {response!r} in {self.path or self.name}; "
                f"known: {', '.join(self.scripts) or 'none'} (add [scripts.\"{key}\"])"
            ) from None

    def clamp(self, pose: Mapping[str, Any]) -> tuple[dict[str, int], list[str]]:
        """Limit a pose to the calibrated ranges.

        Args:
            pose: servo name -> pulse width in microseconds (any number).

        Returns:
            The clamped whole-microsecond pose and the names of servos that were clamped.

        Raises:
            UnknownServo: a servo name the calibration lacks, or a value that is not a finite
                number (nothing is clamped to a guess).
        """
        out: dict[str, int] = {}
        clamped: list[str] = []
        for name, value in pose.items():
            servo = self.servos.get(name)
            if servo is None:
                raise UnknownServo(f"unknown servo {name!r}; known: {', '.join(self.servos)}")
            if (isinstance(value, bool) or not isinstance(value, int | float)
                    or not math.isfinite(value)):
                raise UnknownServo(f"servo {name}: {value!r} is not a pulse width in microseconds")
            out[name] = servo.clamp(value)
            if not servo.min <= value <= servo.max:
                clamped.append(name)
        return out, clamped

    def by_channel(self) -> dict[int, Servo]:
        """Channel number -> servo."""
        return {s.channel: s for s in self.servos.values()}

    def with_servo(self, servo: Servo) -> Calibration:
        """A copy with one servo replaced; direction poses are clamped into its new range."""
        servos = dict(self.servos)
        servos[servo.name] = servo
        directions = {d: {n: (servo.clamp(v) if n == servo.name else v) for n, v in p.items()}
                      for d, p in self.directions.items()}
        return replace(self, servos=servos, directions=directions)


def _failer(path: Path | str) -> Any:
    def fail(key: str, message: str) -> NoReturn:
        raise CalibrationError(f"{path}: {key}: {message}")
    return fail


def _int(value: Any, key: str, fail, lo: int | None = None, hi: int | None = None) -> int:
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        fail(key, f"{value!r} must be a whole number")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        fail(key, f"{value} is outside {lo}..{hi}")
    return value


def _parse_servo(name: str, raw: Any, fail) -> Servo:
    key = f"servos.{name}"
    if not _NAME.match(name):
        fail(key, "a servo name must be lower case letters, digits and _ (like neck_pan)")
    if not isinstance(raw, Mapping):
        fail(key, "must be a table with channel, min, centre, max, speed")
    extra = sorted(set(raw) - _SERVO_KEYS)
    if extra:
        fail(f"{key}.{extra[0]}", f"unknown key; use {', '.join(sorted(_SERVO_KEYS))}")
    for needed in ("channel", "min", "centre", "max", "speed"):
        if needed not in raw:
            fail(f"{key}.{needed}", "missing")
    lo, hi = PULSE_RANGE
    channel = _int(raw["channel"], f"{key}.channel", fail, 0, 31)
    pmin = _int(raw["min"], f"{key}.min", fail, lo, hi)
    centre = _int(raw["centre"], f"{key}.centre", fail, lo, hi)
    pmax = _int(raw["max"], f"{key}.max", fail, lo, hi)
    if not pmin < centre < pmax:
        fail(key, f"need min < centre < max, got {pmin} / {centre} / {pmax}")
    speed = raw["speed"]
    if isinstance(speed, bool) or not isinstance(speed, int | float) or not math.isfinite(speed):
        fail(f"{key}.speed", f"{speed!r} must be a number of microseconds per second")
    if not MIN_SPEED <= speed <= MAX_SPEED:
        fail(f"{key}.speed", f"{speed:g} must be in {MIN_SPEED:g}..{MAX_SPEED:g} microseconds "
             "per second")
    accel = _int(raw.get("acceleration", 0), f"{key}.acceleration", fail, 0, 255)
    return Servo(name, channel, pmin, centre, pmax, float(speed), accel)


def _parse_directions(raw: Any, servos: dict[str, Servo], fail) -> dict[str, dict[str, int]]:
    if not isinstance(raw, Mapping):
        fail("directions", "must be a table of direction = { servo = microseconds }")
    directions: dict[str, dict[str, int]] = {}
    missing = [d for d in DIRECTIONS if d not in raw]
    if missing:
        fail(f"directions.{missing[0]}", f"missing; every head needs {', '.join(DIRECTIONS)}")
    for name, pose in raw.items():
        key = f"directions.{name}"
        if not _NAME.match(name):
            fail(key, "a direction name must be lower case letters, digits and _")
        if not isinstance(pose, Mapping):
            fail(key, f"must be a table of servo = microseconds, got {pose!r}")
        full = {s.name: s.centre for s in servos.values()}
        for servo, value in pose.items():
            if servo not in servos:
                fail(f"{key}.{servo}", f"unknown servo; known: {', '.join(servos)}")
            v = _int(value, f"{key}.{servo}", fail)
            s = servos[servo]
            if not s.min <= v <= s.max:
                fail(f"{key}.{servo}", f"{v} is outside the calibrated range {s.min}..{s.max}")
            full[servo] = v
        directions[name] = full
    return directions


def _read_toml(path: Path) -> dict[str, Any]:
    """The TOML at ``path``: a regular file of at most :data:`head.tomlfile.MAX_BYTES`,
    arrays and inline tables nested at most :data:`head.tomlfile.MAX_NESTING` deep."""
    try:
        text = read_limited(path).decode("utf-8")
    except FileNotFoundError:
        raise CalibrationError(f"{path}: no such calibration file") from None
    except UnicodeDecodeError as exc:
        raise CalibrationError(f"{path}: not a calibration file: byte {exc.start} is not UTF-8 "
                               "text (a binary file?)") from None
    except OSError as exc:
        raise CalibrationError(f"{path}: cannot read: {exc.strerror or exc}") from None
    line = too_deep(text)
    if line is not None:
        raise CalibrationError(f"{path}:{line}: arrays or inline tables nested more than "
                               f"{MAX_NESTING} deep")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CalibrationError(f"{path}: not valid TOML: {exc}") from None


def load_calibration(path: str | Path | None = None) -> Calibration:
    """Load and validate a calibration file.

    Args:
        path: the TOML file; ``None`` means the shipped WHA8030 calibration.

    Returns:
        The validated calibration.

    Raises:
        CalibrationError: one line naming the file, the key and what is wrong.
    """
    path = Path(path) if path is not None else DEFAULT_CALIBRATION
    data = _read_toml(path)
    fail = _failer(path)
    extra = sorted(set(data) - _TOP_KEYS)
    if extra:
        fail(extra[0], f"unknown table; use {', '.join(sorted(_TOP_KEYS))}")
    head = data.get("head", {})
    if not isinstance(head, Mapping):
        fail("head", "must be a table")
    extra = sorted(set(head) - _HEAD_KEYS)
    if extra:
        fail(f"head.{extra[0]}", f"unknown key; use {', '.join(sorted(_HEAD_KEYS))}")
    raw_servos = data.get("servos")
    if not isinstance(raw_servos, Mapping) or not raw_servos:
        fail("servos", "missing; declare at least one [servos.NAME] table")
    servos = {name: _parse_servo(name, raw, fail) for name, raw in raw_servos.items()}
    seen: dict[int, str] = {}
    for s in servos.values():
        if s.channel in seen:
            fail(f"servos.{s.name}.channel",
                 f"channel {s.channel} is also used by {seen[s.channel]}")
        seen[s.channel] = s.name
    directions = _parse_directions(data.get("directions"), servos, fail)
    scripts = parse_scripts(data.get("scripts", {}), "scripts", servos, directions, fail)
    scripts_file = head.get("scripts")
    external: frozenset[str] = frozenset()
    if scripts_file is not None:
        if not isinstance(scripts_file, str):
            fail("head.scripts", f"{scripts_file!r} must be a file name")
        if "\0" in scripts_file:
            fail("head.scripts", f"{scripts_file!r} holds a NUL character; no file name can")
        spath = path.parent / scripts_file
        try:
            sdata = _read_toml(spath)
        except CalibrationError as exc:
            fail("head.scripts", str(exc))
        sfail = _failer(spath)
        if set(sdata) - {"scripts"}:
            sfail(min(set(sdata) - {"scripts"}), "a scripts file holds only [scripts]")
        more = parse_scripts(sdata.get("scripts", {}), "scripts", servos, directions, sfail)
        for name in more:
            if name in scripts:
                sfail(f'scripts."{name}"', f"also defined in {path}")
        external = frozenset(more)
        scripts.update(more)
    protocol = head.get("protocol")
    if protocol is not None and not isinstance(protocol, str):
        fail("head.protocol", f"{protocol!r} must be a protocol name")
    baud = head.get("baudrate")
    if baud is not None:
        baud = _int(baud, "head.baudrate", fail, 300, 4_000_000)
    name = head.get("name", path.stem)
    if not isinstance(name, str):
        fail("head.name", f"{name!r} must be a string")
    tol = _int(head.get("tolerance_us", 20), "head.tolerance_us", fail, 0, 200)
    return Calibration(servos, directions, scripts, name, protocol, baud, tol, path,
                       scripts_file, external)


# ----------------------------------------------------------------------------- writing TOML

def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return str(int(value)) if value.is_integer() else repr(value)
    if isinstance(value, str):
        escaped = value.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
        return f'"{escaped}"'
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}"
                                for k, v in value.items()) + " }" if value else "{}"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {value!r} as TOML")


def _toml_key(key: str) -> str:
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else _toml_value(key)


def dump_calibration(cal: Calibration) -> str:
    """The calibration as TOML text that :func:`load_calibration` reads back unchanged."""
    lines = [
        "# Head calibration for relrl (see docs/head.md). Pulse widths are microseconds,",
        "# speeds microseconds per second. Written by `relrl head calibrate`.",
        "", "[head]", f"name = {_toml_value(cal.name)}",
    ]
    if cal.protocol:
        lines.append(f"protocol = {_toml_value(cal.protocol)}")
    if cal.baudrate:
        lines.append(f"baudrate = {cal.baudrate}")
    lines.append(f"tolerance_us = {cal.tolerance_us}")
    if cal.scripts_file:
        lines.append(f"scripts = {_toml_value(cal.scripts_file)}")
    for s in cal.servos.values():
        lines += ["", f"[servos.{s.name}]", f"channel = {s.channel}", f"min = {s.min}",
                  f"centre = {s.centre}", f"max = {s.max}", f"speed = {_toml_value(s.speed)}"]
        if s.acceleration:
            lines.append(f"acceleration = {s.acceleration}")
    lines += ["", "[directions]"]
    for d, pose in cal.directions.items():
        lines.append(f"{_toml_key(d)} = {_toml_value(pose)}")
    for name, script in cal.scripts.items():
        if name in cal.external_scripts:
            continue
        lines += ["", f"[scripts.{_toml_key(name)}]"]
        if script.doc:
            lines.append(f"doc = {_toml_value(script.doc)}")
        lines.append("steps = [")
        lines += [f"  {_toml_value(step.to_toml_inline())}," for step in script.steps]
        lines.append("]")
    return "\n".join(lines) + "\n"


def save_calibration(cal: Calibration, path: str | Path) -> Path:
    """Write a calibration atomically (temporary file in the same folder, then rename).

    The text is validated by loading it back before the rename, so a bad calibration never
    replaces a good one.

    Returns:
        The path written.

    Raises:
        CalibrationError: the file cannot be written (a folder, a missing folder, no
            permission); nothing is left behind.
    """
    path = Path(path)
    text = dump_calibration(cal)
    if path.exists() and not path.is_file():  # a folder, or a device such as /dev/null
        raise CalibrationError(f"cannot write the calibration to {path}: not a regular file")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp",
                                   dir=path.parent or ".")
    except OSError as exc:
        raise CalibrationError(f"cannot write the calibration to {path}: "
                               f"{exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        load_calibration(tmp)
        mask = os.umask(0o022)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)  # readable like any file the user writes (0644)
        os.replace(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise CalibrationError(f"cannot write the calibration to {path}: "
                                   f"{exc.strerror or exc}") from None
        raise
    return path
