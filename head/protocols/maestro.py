"""Pololu Maestro servo controller (compact binary protocol).

Wire format (facts from the Maestro user's guide, compact protocol):

* ``0x84 ch lo hi`` set target, in quarter microseconds, as two 7-bit halves.
* ``0x87 ch lo hi`` set speed, in 0.25 us per 10 ms (= 25 us/s); 0 would mean unlimited, so
  this driver never sends 0.
* ``0x89 ch lo hi`` set acceleration (0.25 us / 10 ms / 80 ms; 0 = none).
* ``0x90 ch`` get position: two bytes, low first, quarter microseconds.
* ``0xA1`` get errors: two bytes, low first, one bit per error (read and cleared).
"""

from __future__ import annotations

from collections.abc import Sequence

from head.errors import ProtocolError
from head.protocols import Command, Link, Protocol, check_command, check_position

__all__ = ["ERROR_BITS", "Maestro"]

SET_TARGET, SET_SPEED, SET_ACCEL, GET_POSITION, GET_ERRORS = 0x84, 0x87, 0x89, 0x90, 0xA1
#: microseconds per second in one unit of the speed setting.
SPEED_UNIT = 25.0

#: bit -> name of the Maestro error register.
ERROR_BITS: dict[int, str] = {
    0: "serial signal error",
    1: "serial overrun error",
    2: "serial RX buffer full",
    3: "serial CRC error",
    4: "serial protocol error",
    5: "serial timeout",
    6: "script stack error",
    7: "script call stack error",
    8: "script program counter error",
}


def _seven(value: int) -> bytes:
    return bytes((value & 0x7F, (value >> 7) & 0x7F))


class Maestro(Protocol):
    """The Maestro compact protocol: per-channel target and speed, position read-back."""

    name = "maestro"
    baudrate = 9600
    max_channel = 23
    speed_step = SPEED_UNIT

    def setup(self, servos: Sequence[tuple[int, int]]) -> bytes:
        """Set the acceleration of each servo that declares one."""
        return b"".join(bytes((SET_ACCEL, ch)) + _seven(acc) for ch, acc in servos if acc)

    def encode_move(self, commands: Sequence[Command], duration_ms: int) -> bytes:
        """Speed then target for each servo (the controller moves them concurrently)."""
        out = bytearray()
        for cmd in commands:
            check_command(cmd, self.max_channel)
            speed = min(0x3FFF, max(1, round(cmd.speed / SPEED_UNIT)))
            out += bytes((SET_SPEED, cmd.channel)) + _seven(speed)
            out += bytes((SET_TARGET, cmd.channel)) + _seven(cmd.pulse_us * 4)
        return bytes(out)

    def query_positions(self, link: Link, channels: Sequence[int]) -> dict[int, float]:
        """``0x90 ch`` for each channel; quarter microseconds, low byte first.

        Raises:
            ProtocolError: a position that is neither 0 (channel off) nor within
                500..2500 us: not a Maestro answering (wrong baud rate or device).
        """
        out = {}
        for ch in channels:
            lo, hi = link.transact(bytes((GET_POSITION, ch)), 2, f"position of channel {ch}")
            out[ch] = check_position(self.name, link, ch, (lo | hi << 8) / 4.0)
        return out

    def query_moving(self, link: Link, targets: dict[int, int]) -> bool:
        """Moving while any channel's read-back position differs from its target."""
        positions = self.query_positions(link, list(targets))
        return any(positions[ch] != t for ch, t in targets.items())  # exact, in 0.25 us

    def query_errors(self, link: Link) -> list[str]:
        """``0xA1``: the error bits, as names."""
        lo, hi = link.transact(bytes((GET_ERRORS,)), 2, "errors")
        bits = lo | hi << 8
        if bits >> (max(ERROR_BITS) + 1):
            raise ProtocolError(
                f"maestro on {link.port}: error register {bits:#06x} has bits no Maestro sets "
                "(garbage on the line?); check --protocol and the baud rate")
        return [ERROR_BITS[b] for b in range(16) if bits >> b & 1]
