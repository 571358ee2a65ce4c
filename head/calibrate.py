"""Interactive calibration: jog each servo to find its limits, then write the calibration.

Keys are read from a text stream one character at a time (whitespace is ignored), so a
session can be typed, or piped in for a test or a repeatable set-up::

    +  -      step the current servo up / down
    ]  [      bigger / smaller step (1, 5, 10, 25, 50, 100 us)
    m c x     set min / centre / max of the current servo to where it is now
    n  p      next / previous servo
    w         write the calibration file and quit
    q         quit without writing (end of input does the same)
    ?         show the keys

While a servo is being calibrated it may be jogged over the whole absolute range
(500..2500 us), slowly; every other servo stays inside its calibrated limits.

Limits once set are not lost: when the file cannot be written, the port is lost while
jogging, or the session is interrupted (Ctrl-C), the calibration so far is saved to
``head-rescued-YYYYMMDD-HHMMSS.toml`` in the current folder (else the temporary folder) and
the message says where.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import TextIO

from head.base import Head
from head.calibration import PULSE_RANGE, Calibration, dump_calibration, save_calibration
from head.errors import CalibrationError, HeadError

__all__ = ["KEYS", "calibrate"]

STEPS = (1, 5, 10, 25, 50, 100)
#: the fastest a servo is jogged during calibration, microseconds per second.
JOG_SPEED = 200.0

KEYS = """keys: + - step, ] [ step size, m c x set min/centre/max, n p next/previous servo,
w write and quit, q quit without writing, ? help"""


def _keys(stream: TextIO) -> Iterator[str]:
    for line in stream:
        for ch in line:
            if not ch.isspace():
                yield ch


class _Session:
    def __init__(self, head: Head, out: TextIO) -> None:
        self.head = head
        self.out = out
        self.cal: Calibration = head.calibration
        self.names = list(self.cal.servos)
        self.index = 0
        self.step_index = 2
        self.changed = False
        self._select(0)

    @property
    def name(self) -> str:
        return self.names[self.index]

    def say(self, text: str) -> None:
        print(text, file=self.out)

    def _select(self, index: int) -> None:
        """Jog this servo over the absolute range; the others keep their calibrated limits."""
        self.index = index % len(self.names)
        servo = self.cal.servos[self.name]
        wide = dict(self.cal.servos)
        wide[self.name] = replace(servo, min=PULSE_RANGE[0], max=PULSE_RANGE[1])
        self.head.calibration = replace(self.cal, servos=wide)
        self.here = self.head.targets[self.name]
        self.say(f"servo {self.name} (channel {servo.channel}): min {servo.min} "
                 f"centre {servo.centre} max {servo.max}; now at {self.here} us")

    def jog(self, sign: int) -> None:
        lo, hi = PULSE_RANGE
        self.here = min(hi, max(lo, self.here + sign * STEPS[self.step_index]))
        speed = min(JOG_SPEED, self.cal.servos[self.name].speed)
        self.head.move_to({self.name: self.here}, speed=speed)
        self.head.wait()
        self.say(f"{self.name} at {self.here} us")

    def set_limit(self, which: str) -> None:
        servo = self.cal.servos[self.name]
        new = replace(servo, **{which: self.here})
        if not new.min < new.centre < new.max:
            self.say(f"not set: {self.name} needs min < centre < max, "
                     f"would be {new.min} / {new.centre} / {new.max}")
            return
        before = self.cal.directions
        self.cal = self.cal.with_servo(new)
        self.changed = True
        self.say(f"{self.name} {which} = {self.here} us")
        moved = [d for d, pose in self.cal.directions.items() if pose != before[d]]
        if moved:
            self.say(f"note: direction poses {', '.join(moved)} clamped into the new range")

    def finish(self) -> Calibration:
        self.head.calibration = self.cal
        return self.cal


def calibrate(head: Head, keys: TextIO, out: TextIO, path: str | Path) -> Path | None:
    """Run an interactive calibration session on an open head.

    Args:
        head: the head to jog (real or simulated).
        keys: the stream of key presses (stdin in the command line).
        out: where prompts and positions are printed.
        path: the calibration file to write on ``w`` (atomically).

    Returns:
        The path written, or None when the session ended without writing.
    """
    print(KEYS, file=out)
    session = _Session(head, out)
    actions = {
        "+": lambda: session.jog(+1), "=": lambda: session.jog(+1),
        "-": lambda: session.jog(-1),
        "]": lambda: _step(session, +1), "[": lambda: _step(session, -1),
        "m": lambda: session.set_limit("min"), "c": lambda: session.set_limit("centre"),
        "x": lambda: session.set_limit("max"),
        "n": lambda: session._select(session.index + 1),
        "p": lambda: session._select(session.index - 1),
        "?": lambda: session.say(KEYS),
    }
    try:
        for key in _keys(keys):
            if key == "w":
                cal = session.finish()
                try:
                    written = save_calibration(cal, path)
                except CalibrationError as exc:
                    session.changed = False  # rescued below, once
                    raise CalibrationError(f"{exc}; {_rescue(cal, out)}") from None
                session.say(f"wrote {written}")
                return written
            if key == "q":
                break
            action = actions.get(key)
            if action is None:
                session.say(f"unknown key {key!r}; {KEYS}")
                continue
            action()
    except HeadError as exc:  # e.g. the port was lost while jogging
        if not session.changed:
            raise
        raise type(exc)(f"{exc}; {_rescue(session.finish(), out)}") from None
    except KeyboardInterrupt:
        if session.changed:
            session.say(_rescue(session.finish(), out))
        raise
    session.finish()
    session.say("quit without writing" + (" (changes discarded)" if session.changed else ""))
    return None


def _rescue(cal: Calibration, out: TextIO) -> str:
    """Save a calibration that could not be written where asked; says where it went."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for folder in (Path.cwd(), Path(tempfile.gettempdir())):
        try:
            where = save_calibration(cal, folder / f"head-rescued-{stamp}.toml")
        except CalibrationError:
            continue
        return f"the limits set so far were saved to {where}"
    print(dump_calibration(cal), file=out)  # last resort: the text itself
    return "the limits set so far were printed above (no folder was writable)"


def _step(session: _Session, direction: int) -> None:
    session.step_index = min(len(STEPS) - 1, max(0, session.step_index + direction))
    session.say(f"step {STEPS[session.step_index]} us")
