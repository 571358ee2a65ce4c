"""Serial servo-controller protocols, registered by name (one module each).

A protocol turns already-clamped servo targets into bytes and asks the controller questions
over a :class:`Link`. It never decides limits: :meth:`head.calibration.Calibration.clamp`
does, before a protocol sees a value; :func:`check_command` is a last guard that refuses to
encode anything outside the absolute servo range.

Add a protocol by writing a module with a :class:`Protocol` subclass and registering it::

    PROTOCOLS["mine"] = "mypackage.mine:MineProtocol"
"""

from __future__ import annotations

import difflib
import importlib
import math
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar
from typing import Protocol as _Interface

from head.errors import HeadError, UnknownProtocol

__all__ = ["PROTOCOLS", "Command", "Link", "Protocol", "check_command", "check_position",
           "get_protocol"]

#: protocol name -> ``"module:Class"`` (imported on first use).
PROTOCOLS: dict[str, str] = {
    "ssc32": "head.protocols.ssc32:SSC32",
    "maestro": "head.protocols.maestro:Maestro",
    "pms5005": "head.protocols.pms5005:PMS5005",
}

#: the absolute pulse range no encoder will go past, in microseconds.
ABSOLUTE_RANGE = (500, 2500)


@dataclass(frozen=True)
class Command:
    """One servo target, already clamped to the calibration.

    Attributes:
        channel: controller channel.
        pulse_us: pulse width in whole microseconds.
        speed: microseconds per second (positive).
        lo, hi: the servo's calibrated range; an encoder whose units are coarser than a
            microsecond rounds into it, never out of it.
    """

    channel: int
    pulse_us: int
    speed: float
    lo: int = ABSOLUTE_RANGE[0]
    hi: int = ABSOLUTE_RANGE[1]


class Link(_Interface):
    """What a protocol needs from the serial port (see :class:`head.serial_head.SerialLink`)."""

    port: str

    def write(self, data: bytes) -> None:
        """Write every byte or raise :class:`head.errors.PortLost`."""

    def transact(self, data: bytes, size: int, what: str) -> bytes:
        """Write a query and read exactly ``size`` answer bytes (or raise HeadTimeout)."""


def check_command(cmd: Command, max_channel: int) -> None:
    """Refuse a command no servo should get (the last guard before encoding).

    Raises:
        HeadError: the pulse is outside 500..2500 us or the servo's own range, the speed is
            not positive, or the channel does not exist on the controller. Reaching this is
            a bug upstream.
    """
    lo, hi = max(ABSOLUTE_RANGE[0], cmd.lo), min(ABSOLUTE_RANGE[1], cmd.hi)
    if not isinstance(cmd.pulse_us, int) or not lo <= cmd.pulse_us <= hi:
        raise HeadError(f"refusing to send pulse {cmd.pulse_us!r} us to channel {cmd.channel}: "
                        f"outside {lo}..{hi}")
    if not 0 <= cmd.channel <= max_channel:
        raise HeadError(f"channel {cmd.channel} does not exist on this controller "
                        f"(0..{max_channel}); fix the servo's channel in the calibration")
    if not cmd.speed > 0:
        raise HeadError(f"refusing speed {cmd.speed!r} on channel {cmd.channel}: must be > 0")


def check_position(protocol: str, link: Link, channel: int, pulse_us: float) -> float:
    """A position read back from a controller, or :class:`ProtocolError` for garbage.

    0 means the channel sends no pulse (off); anything else outside 500..2500 us is not a
    servo position relrl could have commanded: a wrong baud rate or another device.
    """
    if pulse_us and not ABSOLUTE_RANGE[0] <= pulse_us <= ABSOLUTE_RANGE[1]:
        from head.errors import ProtocolError

        raise ProtocolError(
            f"{protocol} on {link.port}: channel {channel} reports position {pulse_us:g} us, "
            f"outside {ABSOLUTE_RANGE[0]}..{ABSOLUTE_RANGE[1]} (garbage on the line?); check "
            "--protocol and the baud rate")
    return pulse_us


class Protocol(ABC):
    """One servo controller's wire protocol.

    Class attributes:
        name: the registry name.
        baudrate: the default serial speed.
        max_channel: the highest channel number the controller has.
        feedback: whether the controller can report positions and motion.
        speed_step: the unit of the speed field, microseconds per second (0: time-based).
    """

    name: ClassVar[str]
    baudrate: ClassVar[int]
    max_channel: ClassVar[int]
    feedback: ClassVar[bool] = True
    speed_step: ClassVar[float] = 0.0

    def quantise_speed(self, speed: float) -> float:
        """The largest speed the controller can be told that is not above ``speed``.

        ``speed_step`` is the unit of the protocol's speed field (0: any speed works, as for
        time-based protocols). Speeds are at least 25 us/s, a multiple of every unit here.
        """
        if not self.speed_step:
            return speed
        return max(self.speed_step, math.floor(speed / self.speed_step) * self.speed_step)

    def setup(self, servos: Sequence[tuple[int, int]]) -> bytes:
        """Bytes to send once after opening; ``servos`` is ``(channel, acceleration)``."""
        return b""

    @abstractmethod
    def encode_move(self, commands: Sequence[Command], duration_ms: int) -> bytes:
        """Bytes that move the listed servos together.

        Args:
            commands: the servo targets (validated with :func:`check_command`).
            duration_ms: the expected duration of the move (longest servo), for protocols that
                take a time instead of a speed.
        """

    def query_moving(self, link: Link, targets: dict[int, int]) -> bool:
        """Ask whether any servo is still moving (``targets``: channel -> last target, us).

        Raises:
            HeadError: the protocol has no feedback (:attr:`feedback` false)."""
        raise HeadError(f"the {self.name} protocol cannot report motion (no feedback)")

    def query_positions(self, link: Link, channels: Sequence[int]) -> dict[int, float]:
        """Ask the current pulse width of each channel, in microseconds.

        Raises:
            HeadError: the protocol has no feedback (:attr:`feedback` false)."""
        raise HeadError(f"the {self.name} protocol cannot report positions (no feedback)")

    def query_errors(self, link: Link) -> list[str]:
        """Ask the controller for its error flags (empty when it has none to report)."""
        return []


def get_protocol(name: str) -> Protocol:
    """A new protocol object by registry name.

    Raises:
        UnknownProtocol: the name is not registered (suggests the closest one).
    """
    target = PROTOCOLS.get(str(name).lower())
    if target is None:
        close = difflib.get_close_matches(str(name).lower(), PROTOCOLS, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise UnknownProtocol(f"unknown protocol {name!r}{hint} "
                              f"(known: {', '.join(sorted(PROTOCOLS))})")
    modname, _, clsname = target.partition(":")
    cls = getattr(importlib.import_module(modname), clsname)
    return cls()
