"""Dr Robot PMS5005 sensing and motion controller (the WHA8030 head's board).

Packet (facts from Dr Robot's WiRobot protocol documents)::

    5E 02 | RID=01 | 00 | DID | LEN | DATA (LEN bytes) | CRC | 5E 0D

The CRC is CRC-8/Maxim (Dallas 1-Wire: reflected polynomial 0x8C, initial value 0) over
RID .. DATA. Servo commands used here:

* DID 29 (all servos, with time): six 16-bit values, low byte first, one per channel 0..5,
  then the time in milliseconds (16 bit, low first). A value is the pulse width in
  milliseconds times 2250 (1.5 ms -> 3375); ``0x8000`` leaves a channel as it is.

The PMS5005 does not report hobby-servo positions, so the head estimates motion from the
calibrated speeds (:attr:`feedback` is false).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from head.protocols import Command, Protocol, check_command

__all__ = ["NO_CONTROL", "PMS5005", "crc8_maxim", "packet", "pulse_to_value"]

STX, ETX = b"\x5e\x02", b"\x5e\x0d"
RID = 0x01
SERVO_ALL_TIME_DID = 29
NO_CONTROL = 0x8000
CHANNELS = 6


def crc8_maxim(data: bytes) -> int:
    """CRC-8/Maxim (poly 0x31 reflected = 0x8C, init 0, no final xor)."""
    crc = 0
    for byte in data:
        for _ in range(8):
            mix = (crc ^ byte) & 1
            crc >>= 1
            if mix:
                crc ^= 0x8C
            byte >>= 1
    return crc


def packet(did: int, data: bytes) -> bytes:
    """A complete PMS5005 packet with header, length, CRC and trailer."""
    body = bytes((RID, 0x00, did, len(data))) + data
    return STX + body + bytes((crc8_maxim(body),)) + ETX


def pulse_to_value(pulse_us: int, lo: int = 500, hi: int = 2500) -> int:
    """Microseconds -> the PMS5005 servo command value (ms x 2250), kept inside [lo, hi].

    One unit is 0.44 us, so the nearest value can land a fraction of a microsecond past a
    limit; it is then moved one unit back inside.
    """
    return min(math.floor(hi * 2.25), max(math.ceil(lo * 2.25), round(pulse_us * 2.25)))


class PMS5005(Protocol):
    """Dr Robot PMS5005: one timed packet moves all servos together."""

    name = "pms5005"
    baudrate = 115200
    max_channel = CHANNELS - 1
    feedback = False

    def encode_move(self, commands: Sequence[Command], duration_ms: int) -> bytes:
        """One DID 29 packet: the listed channels move, the others are left alone."""
        if not commands:
            return b""
        values = [NO_CONTROL] * CHANNELS
        for cmd in commands:
            check_command(cmd, self.max_channel)
            values[cmd.channel] = pulse_to_value(cmd.pulse_us, cmd.lo, cmd.hi)
        ms = min(0xFFFF, max(0, int(duration_ms)))
        data = b"".join(v.to_bytes(2, "little") for v in values) + ms.to_bytes(2, "little")
        return packet(SERVO_ALL_TIME_DID, data)
