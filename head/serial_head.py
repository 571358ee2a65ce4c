"""The serial head: a calibrated head behind a servo controller on a serial port.

``port`` is anything pyserial opens: a device (``/dev/ttyUSB0``, ``COM3``) or a URL
(``loop://``, ``socket://host:port``, ``rfc2217://...``). The protocol (``ssc32``,
``maestro``, ``pms5005``) is looked up by name in :mod:`head.protocols`.

Every pose is clamped by :meth:`head.calibration.Calibration.clamp` before it reaches the
protocol, and the protocol refuses anything outside 500..2500 us, so no input can put an
out-of-range pulse on the wire. Serial failures become :class:`PortUnavailable` (cannot
open), :class:`PortLost` (failed in use; call ``reopen()``) or :class:`HeadTimeout`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from head.base import Head, MotionModel
from head.calibration import Calibration, load_calibration
from head.errors import HeadTimeout, PortLost, PortUnavailable, ProtocolError
from head.protocols import Command, Protocol, get_protocol

__all__ = ["SerialHead", "SerialLink"]

#: seconds to wait for an answer byte before :class:`HeadTimeout`.
DEFAULT_TIMEOUT = 0.5


class SerialLink:
    """A pyserial port with errors turned into head errors that name the port."""

    def __init__(self, port: str, baudrate: int, timeout: float, protocol: str,
                 factory: Callable[..., Any] | None = None) -> None:
        import serial  # lazy: the engine and simulator run without pyserial

        self.port = port
        self.protocol = protocol
        self.timeout = timeout
        self.bytes_written = 0
        self._serial_errors: tuple[type[BaseException], ...] = (serial.SerialException, OSError)
        try:  # pyserial's POSIX port lets termios errors through (e.g. a hung-up terminal)
            import termios

            self._serial_errors += (termios.error,)
        except ImportError:  # pragma: no cover - Windows
            pass
        opener = factory or serial.serial_for_url
        try:
            self.serial = opener(port, baudrate=baudrate, timeout=timeout,
                                 write_timeout=max(timeout, 1.0))
        except (serial.SerialException, OSError, ValueError) as exc:
            reason = getattr(exc, "strerror", None) or str(exc).splitlines()[0]
            raise PortUnavailable(
                f"cannot open serial port {port!r}: {reason}; check the cable and the device "
                "path (ls /dev/ttyUSB* /dev/ttyACM*), or give sim for the simulated "
                "head") from None

    def _lost(self, exc: BaseException) -> PortLost:
        reason = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
        return PortLost(f"lost serial port {self.port!r} ({self.protocol}): {reason}; "
                        "reconnect the controller and call reopen()")

    def write(self, data: bytes) -> None:
        """Write every byte or raise :class:`PortLost`."""
        if not data:
            return
        try:
            n = self.serial.write(data)
            self.serial.flush()
        except self._serial_errors as exc:
            raise self._lost(exc) from None
        if n is not None and n != len(data):
            raise PortLost(f"serial port {self.port!r} accepted {n} of {len(data)} bytes; "
                           "reconnect the controller and call reopen()")
        self.bytes_written += len(data)

    def transact(self, data: bytes, size: int, what: str) -> bytes:
        """Write a query and read exactly ``size`` bytes of answer.

        Raises:
            HeadTimeout: fewer than ``size`` bytes arrived within the timeout.
            PortLost: the port failed.
        """
        try:
            self.serial.reset_input_buffer()
        except self._serial_errors as exc:
            raise self._lost(exc) from None
        self.write(data)
        try:
            answer = self.serial.read(size)
        except self._serial_errors as exc:
            raise self._lost(exc) from None
        if len(answer) < size:
            raise HeadTimeout(
                f"{self.protocol} controller on {self.port!r} did not answer {what} within "
                f"{self.timeout:g} s (got {len(answer)} of {size} bytes); check power, cable, "
                "baud rate and --protocol")
        try:
            extra = int(getattr(self.serial, "in_waiting", 0) or 0)
        except self._serial_errors as exc:
            raise self._lost(exc) from None
        if extra:
            raise ProtocolError(
                f"{self.protocol} controller on {self.port!r} answered {what} with {extra} "
                f"bytes more than the {size} asked (garbage on the line?); check --protocol "
                "and the baud rate")
        return bytes(answer)

    def close(self) -> None:
        """Close the port; never raises."""
        try:
            self.serial.close()
        except self._serial_errors:
            pass


class SerialHead(Head):
    """A head driven through a servo controller on a serial port.

    Args:
        port: device path or pyserial URL.
        protocol: registry name; default: the calibration's ``[head] protocol``.
        calibration: the calibration (default: the shipped WHA8030 file).
        timeout: seconds to wait for each answer.
        feedback: ask the controller for positions and motion (default: when the protocol
            can, except on ``loop://``, which only echoes). Without feedback the head
            estimates positions from the calibrated speeds.
        serial_factory: replaces ``serial.serial_for_url`` (tests use an in-memory twin).
        clock, sleep: the head's time source (tests pass a fake clock).
    """

    def __init__(self, port: str, protocol: str | Protocol | None = None,
                 calibration: Calibration | None = None, *, timeout: float = DEFAULT_TIMEOUT,
                 feedback: bool | None = None, baudrate: int | None = None,
                 serial_factory: Callable[..., Any] | None = None,
                 clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        super().__init__(calibration or load_calibration())
        cal = self.calibration
        name = protocol or cal.protocol
        if name is None:
            from head.errors import UnknownProtocol
            raise UnknownProtocol("no protocol given; pass --protocol (ssc32, maestro, pms5005) "
                                  f"or set [head] protocol in {cal.path}")
        self.protocol = name if isinstance(name, Protocol) else get_protocol(name)
        for servo in cal.servos.values():
            if servo.channel > self.protocol.max_channel:
                from head.errors import CalibrationError
                raise CalibrationError(
                    f"{cal.path}: servos.{servo.name}.channel: {servo.channel} does not exist "
                    f"on a {self.protocol.name} controller (0..{self.protocol.max_channel})")
        self.port = port
        self.timeout = timeout
        self.baudrate = baudrate or cal.baudrate or self.protocol.baudrate
        can = self.protocol.feedback and not str(port).startswith("loop://")
        self.feedback = can if feedback is None else (feedback and self.protocol.feedback)
        self._factory = serial_factory
        self._clock, self._sleeper = clock, sleep
        self._model = MotionModel({n: float(v) for n, v in self.targets.items()})
        self.link: SerialLink | None = None
        self._bytes_before = 0
        self._open()
        self._closed = False

    def _open(self) -> None:
        self.link = SerialLink(self.port, self.baudrate, self.timeout, self.protocol.name,
                               self._factory)
        try:
            servos = [(s.channel, s.acceleration) for s in self.calibration.servos.values()]
            self.link.write(self.protocol.setup(servos))
            if self.feedback:  # start the estimate from where the servos really are
                self._model = MotionModel(self.positions())
            # A head starts looking forward, at the caregiver.
            self._closed = False
            self.move_to(self.calibration.centre_pose())
        except BaseException:
            self._release()
            raise

    def _release(self) -> None:
        if self.link is not None:
            self._bytes_before += self.link.bytes_written
            self.link.close()
            self.link = None

    @property
    def bytes_written(self) -> int:
        """Every byte written since this head was created (over reopens too)."""
        return self._bytes_before + (self.link.bytes_written if self.link else 0)

    def _live_link(self) -> SerialLink:
        if self.link is None:
            raise PortLost(f"serial port {self.port!r} is closed; call reopen()")
        return self.link

    def _command(self, pose: dict[str, int], speeds: dict[str, float]) -> float:
        servos = self.calibration.servos
        duration = self._model.command(self._clock(), pose, speeds)
        commands = [Command(servos[n].channel, v, speeds[n], servos[n].min, servos[n].max)
                    for n, v in pose.items()]
        self._live_link().write(self.protocol.encode_move(commands, round(duration * 1000)))
        return duration

    def _quantise_speed(self, speed: float) -> float:
        return self.protocol.quantise_speed(speed)

    def _channels(self) -> dict[str, int]:
        return {n: s.channel for n, s in self.calibration.servos.items()}

    def positions(self) -> dict[str, float]:
        """Read back from the controller when it can; otherwise the speed-based estimate."""
        if not self.feedback:
            return self._model.at(self._clock())
        channels = self._channels()
        raw = self.protocol.query_positions(self._live_link(), list(channels.values()))
        return {n: raw[ch] for n, ch in channels.items()}

    def is_moving(self) -> bool:
        """Ask the controller when it can; otherwise the speed-based estimate."""
        if not self.feedback:
            return self._model.moving(self._clock())
        targets = {self.calibration.servos[n].channel: v for n, v in self.targets.items()}
        return self.protocol.query_moving(self._live_link(), targets)

    def _errors(self) -> list[str]:
        return self.protocol.query_errors(self._live_link()) if self.feedback else []

    def status(self) -> dict[str, Any]:
        """As :meth:`Head.status`, plus the port, protocol and bytes written."""
        out = super().status()
        out.update(port=self.port, protocol=self.protocol.name, feedback=self.feedback,
                   bytes_written=self.bytes_written)
        return out

    def _now(self) -> float:
        return self._clock()

    def _sleep(self, seconds: float) -> None:
        self._sleeper(seconds)
