"""Lynxmotion SSC-32 servo controller (ASCII protocol).

Wire format (facts from the SSC-32 manual):

* group move: ``#<ch>P<pw>S<spd>`` repeated for each servo, then ``\\r``; the servos of one
  line start and end together. ``pw`` is microseconds (500..2500), ``S`` microseconds per
  second.
* ``Q\\r`` answers one byte: ``.`` when the previous move is done, ``+`` while moving.
* ``QP <ch>`` (several in one line, then ``\\r``) answers one byte per channel: the pulse
  width divided by 10.

The SSC-32 has no error register; :meth:`query_errors` reports nothing.
"""

from __future__ import annotations

from collections.abc import Sequence

from head.errors import ProtocolError
from head.protocols import Command, Link, Protocol, check_command, check_position

__all__ = ["SSC32"]


class SSC32(Protocol):
    """The SSC-32 ASCII protocol: group moves with per-servo speed."""

    name = "ssc32"
    baudrate = 115200
    max_channel = 31
    speed_step = 1.0

    def encode_move(self, commands: Sequence[Command], duration_ms: int) -> bytes:
        """``#0P1500S600#1P1400S400\\r`` for a group of servos moving together."""
        parts = []
        for cmd in commands:
            check_command(cmd, self.max_channel)
            parts.append(f"#{cmd.channel}P{cmd.pulse_us}S{max(1, round(cmd.speed))}")
        return ("".join(parts) + "\r").encode("ascii") if parts else b""

    def query_moving(self, link: Link, targets: dict[int, int]) -> bool:
        """Send ``Q`` and read ``.`` (done) or ``+`` (moving)."""
        answer = link.transact(b"Q\r", 1, "move status (Q)")
        if answer == b"+":
            return True
        if answer == b".":
            return False
        raise ProtocolError(f"ssc32 on {link.port}: answer {answer!r} to Q is neither '.' nor "
                            "'+'; check the protocol and baud rate")

    def query_positions(self, link: Link, channels: Sequence[int]) -> dict[int, float]:
        """Send ``QP`` for each channel; each answer byte is the pulse width / 10 (0: no
        pulse); anything else outside 500..2500 us is a :class:`ProtocolError`."""
        if not channels:
            return {}
        query = " ".join(f"QP {ch}" for ch in channels) + "\r"
        answer = link.transact(query.encode("ascii"), len(channels), "positions (QP)")
        return {ch: check_position(self.name, link, ch, float(b * 10))
                for ch, b in zip(channels, answer, strict=True)}
