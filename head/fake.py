"""A fake servo controller: the software twin of the SSC-32, Maestro and PMS5005 boards.

:class:`FakeController` decodes a protocol byte by byte, checks every byte (command codes,
7-bit data bytes, line grammar, packet framing, CRC), moves its servos at the commanded
speed and answers queries like the real board. Anything a real board would reject, and any
pulse outside ``limits``, is recorded in :attr:`FakeController.violations`.

Two ways to put it behind a head:

* :class:`PtyController` runs it in a thread behind a pseudo-terminal; its :attr:`port` is a
  real ``/dev/pts/N`` path any serial program (``relrl head --port ...``) can open.
* :class:`FakeSerial` is an in-process stand-in for a pyserial port (fast property tests).

The decoders here are written independently of the encoders in :mod:`head.protocols`, so a
test that passes both checks the wire format, not one function against itself.
"""

from __future__ import annotations

import os
import random
import re
import select
import threading
import time
import tty
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ClassVar, Self

__all__ = ["FakeController", "FakeSerial", "PtyController", "crc8_maxim_reflected"]


def crc8_maxim_reflected(data: bytes) -> int:
    """CRC-8/Maxim computed the long way: reflect, MSB-first with poly 0x31, reflect back."""
    def reflect(v: int) -> int:
        return int(f"{v:08b}"[::-1], 2)
    crc = 0
    for byte in data:
        crc ^= reflect(byte)
        for _ in range(8):
            crc = ((crc << 1) ^ 0x31) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return reflect(crc)


@dataclass
class _Servo:
    pos: float = 1500.0
    target: float = 1500.0
    speed: float = 0.0  # us/s; 0 = instant
    t0: float = 0.0
    start: float = 1500.0

    def at(self, now: float) -> float:
        if self.speed <= 0:
            return self.target
        step = self.speed * max(0.0, now - self.t0)
        d = self.target - self.start
        return self.target if abs(d) <= step else self.start + (step if d > 0 else -step)


@dataclass
class FakeController:
    """A servo controller that checks every byte it receives.

    Attributes:
        protocol: ``ssc32``, ``maestro`` or ``pms5005``.
        limits: channel -> (min, max) microseconds; pulses outside are violations.
        mute: when true, never answer (to test timeouts).
        garbage: when true, every answer has the right length but random bytes (a wrong
            baud rate, another device on the port); what it receives is still checked.
        moves: every decoded move, as channel -> pulse in microseconds.
        violations: one line per protocol error or out-of-limit pulse.
        bytes_checked: how many bytes went through the decoder.
        error_bits: the Maestro error register (read and cleared by ``0xA1``).
    """

    protocol: str
    limits: dict[int, tuple[int, int]] = field(default_factory=dict)
    mute: bool = False
    garbage: bool = False
    clock: Callable[[], float] = time.monotonic
    moves: list[dict[int, int]] = field(default_factory=list)
    violations: list[str] = field(default_factory=list)
    queries: list[str] = field(default_factory=list)
    bytes_checked: int = 0
    error_bits: int = 0

    def __post_init__(self) -> None:
        try:
            self._push = {"ssc32": self._ssc32, "maestro": self._maestro,
                          "pms5005": self._pms5005}[self.protocol]
        except KeyError:
            raise ValueError(f"no fake controller for protocol {self.protocol!r}") from None
        self.servos: dict[int, _Servo] = {}
        self._buf = bytearray()
        self._speeds: dict[int, float] = {}
        self._lock = threading.Lock()
        self._noise = random.Random(0)

    # -- shared -------------------------------------------------------------------------------

    def feed(self, data: bytes) -> bytes:
        """Decode bytes; returns the controller's answers."""
        out = bytearray()
        with self._lock:
            for byte in data:
                self.bytes_checked += 1
                out += self._push(byte)
            if self.garbage:
                out = bytearray(self._noise.randrange(256) for _ in out)
        return b"" if self.mute else bytes(out)

    def _bad(self, text: str) -> bytes:
        self.violations.append(f"{self.protocol}: {text}")
        self._buf.clear()
        return b""

    def _move(self, targets: dict[int, tuple[float, float]]) -> None:
        """Start a move: channel -> (pulse us, speed us/s; 0 = instant)."""
        now = self.clock()
        for ch, (pulse, speed) in targets.items():
            lo, hi = self.limits.get(ch, (500, 2500))
            if not (lo <= pulse <= hi and 500 <= pulse <= 2500):
                self.violations.append(f"{self.protocol}: channel {ch} pulse {pulse:g} us "
                                       f"outside {lo}..{hi}")
            s = self.servos.setdefault(ch, _Servo())
            s.start = s.at(now)
            s.target, s.speed, s.t0 = float(pulse), speed, now
        self.moves.append({ch: round(p) for ch, (p, _) in targets.items()})

    def position(self, channel: int) -> float:
        """Where a channel's servo is now (1500 us before any command)."""
        s = self.servos.get(channel)
        return 1500.0 if s is None else s.at(self.clock())

    def moving(self) -> bool:
        """Whether any servo has not reached its target."""
        now = self.clock()
        return any(abs(s.at(now) - s.target) > 0.01 for s in self.servos.values())

    # -- SSC-32: ASCII lines ending in CR -------------------------------------------------------

    _SSC_MOVE = re.compile(r"(?:#\d{1,2}P\d{3,4}(?:S\d{1,5})?)+(?:T\d{1,5})?")
    _SSC_QP = re.compile(r"QP \d{1,2}(?: QP \d{1,2})*")

    def _ssc32(self, byte: int) -> bytes:
        ch = chr(byte)
        if byte != 0x0D:
            if not (ch.isdigit() or ch in "#PSTQ "):
                return self._bad(f"byte {byte:#04x} is not allowed in a command line")
            self._buf.append(byte)
            if len(self._buf) > 512:
                return self._bad("line longer than 512 bytes without CR")
            return b""
        line = self._buf.decode("ascii")
        self._buf.clear()
        if line == "Q":
            self.queries.append("Q")
            return b"+" if self.moving() else b"."
        if self._SSC_QP.fullmatch(line):
            chans = [int(c) for c in re.findall(r"\d+", line)]
            self.queries.append(line)
            return bytes(min(255, round(self.position(c) / 10)) for c in chans)
        if self._SSC_MOVE.fullmatch(line):
            targets = {}
            for chan, pw, spd in re.findall(r"#(\d+)P(\d+)(?:S(\d+))?", line):
                if int(chan) > 31:
                    return self._bad(f"channel {chan} does not exist")
                targets[int(chan)] = (float(pw), float(spd or 0))
            self._move(targets)
            return b""
        return self._bad(f"cannot parse line {line!r}")

    # -- Maestro compact protocol -------------------------------------------------------------

    _MAESTRO_LEN: ClassVar[dict[int, int]] = {0x84: 3, 0x87: 3, 0x89: 3, 0x90: 1, 0xA1: 0}

    def _maestro(self, byte: int) -> bytes:
        if not self._buf:
            if byte not in self._MAESTRO_LEN:
                return self._bad(f"unknown command byte {byte:#04x}")
        elif byte & 0x80:
            return self._bad(f"data byte {byte:#04x} has its top bit set")
        self._buf.append(byte)
        cmd = self._buf[0]
        if len(self._buf) <= self._MAESTRO_LEN[cmd]:
            return b""
        args = bytes(self._buf[1:])
        self._buf.clear()
        if cmd == 0xA1:
            self.queries.append("errors")
            bits, self.error_bits = self.error_bits, 0
            return bytes((bits & 0xFF, bits >> 8 & 0xFF))
        chan = args[0]
        if chan > 23:
            return self._bad(f"channel {chan} does not exist")
        if cmd == 0x90:
            self.queries.append(f"position {chan}")
            return round(self.position(chan) * 4).to_bytes(2, "little")
        value = args[1] | args[2] << 7
        if cmd == 0x87:
            self._speeds[chan] = value * 25.0
        elif cmd == 0x84:
            self._move({chan: (value / 4.0, self._speeds.get(chan, 0.0))})
        return b""

    # -- PMS5005 packets --------------------------------------------------------------------------

    def _pms5005(self, byte: int) -> bytes:
        buf = self._buf
        n = len(buf)
        fixed = {0: 0x5E, 1: 0x02, 2: 0x01, 3: 0x00}
        if n in fixed and byte != fixed[n]:
            return self._bad(f"byte {n} of a packet is {byte:#04x}, expected {fixed[n]:#04x}")
        buf.append(byte)
        if n < 6:
            return b""
        length = buf[5]
        if n == 6 + length + 1 and byte != 0x5E:
            return self._bad(f"ETX0 is {byte:#04x}, expected 0x5e")
        if n < 6 + length + 2:
            return b""
        if byte != 0x0D:
            return self._bad(f"ETX1 is {byte:#04x}, expected 0x0d")
        packet = bytes(buf)
        buf.clear()
        body, crc = packet[2:6 + length], packet[6 + length]
        if crc8_maxim_reflected(body) != crc:
            return self._bad(f"CRC {crc:#04x} wrong, expected {crc8_maxim_reflected(body):#04x}")
        did, data = packet[4], packet[6:6 + length]
        if did == 29 and length == 14:
            ms = int.from_bytes(data[12:14], "little")
            targets = {}
            now = self.clock()
            for ch in range(6):
                value = int.from_bytes(data[2 * ch:2 * ch + 2], "little")
                if value == 0x8000:
                    continue
                pulse = value / 2.25
                dist = abs(pulse - self.position(ch))
                targets[ch] = (pulse, dist / (ms / 1000) if ms else 0.0)
            del now
            self._move(targets)
            return b""
        return self._bad(f"unsupported packet DID {did} with {length} data bytes")


class FakeSerial:
    """An in-process stand-in for a pyserial port, wired to a :class:`FakeController`."""

    def __init__(self, controller: FakeController, timeout: float | None = 0.1) -> None:
        self.controller = controller
        self.timeout = timeout
        self.is_open = True
        self.written = bytearray()
        self._rx = bytearray()

    def write(self, data: bytes) -> int:
        """Feed bytes to the controller; its answers become readable."""
        if not self.is_open:
            raise OSError(5, "Input/output error")
        self.written += data
        self._rx += self.controller.feed(bytes(data))
        return len(data)

    def read(self, size: int = 1) -> bytes:
        """Up to ``size`` answer bytes (fewer means a timeout)."""
        if not self.is_open:
            raise OSError(5, "Input/output error")
        out, self._rx = bytes(self._rx[:size]), self._rx[size:]
        return out

    def reset_input_buffer(self) -> None:
        """Drop unread answers."""
        self._rx.clear()

    def flush(self) -> None:
        """Nothing is buffered."""

    def close(self) -> None:
        """Close; safe twice."""
        self.is_open = False


class PtyController:
    """A :class:`FakeController` behind a pseudo-terminal, served by a thread.

    Use as a context manager; :attr:`port` is the device path to open. :meth:`hang_up`
    closes the controller's end, as if the cable were pulled.
    """

    def __init__(self, controller: FakeController) -> None:
        self.controller = controller
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)
        self.port = os.ttyname(self._slave)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="fake-servo-controller",
                                        daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                ready, _, _ = select.select([self._master], [], [], 0.02)
                if not ready:
                    continue
                data = os.read(self._master, 4096)
            except (OSError, ValueError):
                return
            answer = self.controller.feed(data)
            if answer:
                try:
                    os.write(self._master, answer)
                except OSError:
                    return

    def hang_up(self) -> None:
        """Stop answering and close the controller's end of the terminal."""
        self._stop.set()
        self._thread.join(timeout=2)
        for fd in (self._master, self._slave):
            try:
                os.close(fd)
            except OSError:
                pass
        self._master = self._slave = -1

    def close(self) -> None:
        """Stop the thread and close the terminal; safe twice."""
        if self._master != -1:
            self.hang_up()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
