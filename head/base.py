"""The one head interface, shared by the simulated head and the serial head.

:class:`Head` holds everything that does not depend on the wire: clamping every pose to the
calibration, playing motor scripts, waiting for moves, naming the direction the head looks
at, and returning to centre on close. Subclasses provide a clock, a way to sleep, and the
three device hooks ``_command``, ``positions`` and ``is_moving``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import TracebackType
from typing import Any, Self

from head.calibration import MIN_SPEED, Calibration
from head.errors import HeadClosed, HeadError, HeadTimeout
from head.scripts import Step

__all__ = ["Head", "MotionModel"]

#: how often :meth:`Head.wait` polls, in seconds.
POLL_S = 0.01
#: slack added to a move's expected duration before :meth:`Head.wait` gives up, in seconds.
WAIT_SLACK_S = 1.0
#: times closer than this (seconds) count as equal, so float round-off never leaves a servo
#: a hair short of its target.
TIME_EPS = 1e-9


@dataclass
class MotionModel:
    """Where servos are, given the moves commanded: straight lines at constant speed.

    The simulated head uses it with simulated time; the serial head uses it with the wall
    clock for controllers that cannot report positions.
    """

    start: dict[str, float]
    target: dict[str, float] = field(default_factory=dict)
    speed: dict[str, float] = field(default_factory=dict)
    t0: float = 0.0

    def __post_init__(self) -> None:
        self.target = self.target or dict(self.start)
        self.speed = self.speed or {name: 1.0 for name in self.start}

    def at(self, now: float) -> dict[str, float]:
        """Every servo's position at time ``now`` (exactly the target once it has arrived)."""
        out = {}
        for name, p0 in self.start.items():
            goal, speed = self.target[name], self.speed[name]
            elapsed = now - self.t0
            if elapsed + TIME_EPS >= abs(goal - p0) / speed:
                out[name] = goal
            else:
                step = speed * max(0.0, elapsed)
                out[name] = p0 + (step if goal > p0 else -step)
        return out

    def end_time(self) -> float:
        """When the last servo of the current move arrives."""
        return self.t0 + max((abs(self.target[n] - p) / self.speed[n]
                              for n, p in self.start.items()), default=0.0)

    def moving(self, now: float) -> bool:
        """Whether any servo is still on its way at ``now``."""
        return now + TIME_EPS < self.end_time()

    def command(self, now: float, pose: Mapping[str, int], speeds: Mapping[str, float]) -> float:
        """Start a move from where the servos are at ``now``; returns its duration in s.

        The duration is until every servo arrives, including servos still on their way to
        an earlier target.
        """
        self.start = self.at(now)
        # servos left out of the pose keep going to their previous targets
        self.target = {**self.target, **{n: float(v) for n, v in pose.items()}}
        self.speed = {**self.speed, **speeds}
        self.t0 = now
        return self.end_time() - now


class Head(ABC):
    """A robotic head: servos with calibrated limits, looking in named directions.

    Use it as a context manager; ``close()`` returns to centre and is safe twice.
    """

    def __init__(self, calibration: Calibration) -> None:
        self.calibration = calibration
        self.targets: dict[str, int] = calibration.centre_pose()
        self.clamped_count = 0
        self.last_move_s = 0.0
        self._closed = True

    # -- device hooks -----------------------------------------------------------------------

    @abstractmethod
    def _open(self) -> None:
        """Acquire the device."""

    @abstractmethod
    def _release(self) -> None:
        """Release the device (must not raise when it is already gone)."""

    @abstractmethod
    def _command(self, pose: dict[str, int], speeds: dict[str, float]) -> float:
        """Send an already clamped pose; returns the expected duration in seconds."""

    @abstractmethod
    def positions(self) -> dict[str, float]:
        """Servo name -> current pulse width in microseconds."""

    @abstractmethod
    def is_moving(self) -> bool:
        """Whether any servo is still moving."""

    @abstractmethod
    def _now(self) -> float:
        """The head's clock, in seconds."""

    @abstractmethod
    def _sleep(self, seconds: float) -> None:
        """Let ``seconds`` pass on the head's clock."""

    def _quantise_speed(self, speed: float) -> float:
        """The speed the device will really use for a requested one (never faster)."""
        return speed

    def _errors(self) -> list[str]:
        """Errors the device reports (none by default)."""
        return []

    # -- the interface ----------------------------------------------------------------------

    def _check_open(self) -> None:
        if self._closed:
            raise HeadClosed("the head is closed; call reopen() or open a new one")

    def move_to(self, pose: Mapping[str, float], speed: float | None = None) -> dict[str, int]:
        """Move some servos; every value is clamped to the calibrated range first.

        Args:
            pose: servo name -> pulse width in microseconds (servos left out stay put).
            speed: optional speed in microseconds per second; never faster than a servo's
                calibrated speed, never slower than 25 us/s.

        Returns:
            The pose actually commanded (after clamping).

        Raises:
            UnknownServo: an unknown servo name or a value that is not a finite number.
            HeadError: a non-positive speed.
        """
        self._check_open()
        clamped, over = self.calibration.clamp(pose)
        if speed is not None and not (isinstance(speed, int | float) and speed > 0):
            raise HeadError(f"speed {speed!r} must be a positive number of microseconds/second")
        servos = self.calibration.servos
        speeds = {n: self._quantise_speed(max(MIN_SPEED, min(float(speed), servos[n].speed)
                                              if speed else servos[n].speed))
                  for n in clamped}
        self.clamped_count += len(over)
        if clamped:
            self.last_move_s = self._command(clamped, speeds)
            self.targets.update(clamped)
        return clamped

    def look(self, direction: str) -> dict[str, int]:
        """Start turning towards a direction (``left`` ... ``centre``); does not wait."""
        return self.move_to(self.calibration.pose_of(direction))

    def wait(self, timeout: float | None = None) -> bool:
        """Wait until the current move ends.

        Args:
            timeout: seconds on the head's clock; default: the move's expected duration
                plus one second.

        Returns:
            True when the head stopped, False when the timeout passed first.
        """
        self._check_open()
        limit = self.last_move_s + WAIT_SLACK_S if timeout is None else timeout
        deadline = self._now() + limit
        while self.is_moving():
            left = deadline - self._now()
            if left <= 0:
                return False
            self._sleep(min(POLL_S, left))
        return True

    def _step_pose(self, step: Step, start: Mapping[str, int]) -> dict[str, float]:
        if step.kind == "direction":
            return dict(self.calibration.pose_of(step.direction or ""))
        if step.kind == "offset":
            return {n: v + step.values.get(n, 0.0) for n, v in start.items()}
        return dict(step.values)

    def emit(self, response: str) -> None:
        """Play the motor script of a response (the control loop's actuator).

        Args:
            response: the response term as text, e.g. ``"look(left_down)"``.

        Raises:
            UnknownResponse: no script for that response in the calibration.
            HeadTimeout: a step did not finish in its expected time plus one second.
        """
        self._check_open()
        script = self.calibration.script_for(response)
        start = dict(self.targets)
        for i, step in enumerate(script.steps):
            self.move_to(self._step_pose(step, start), step.speed)
            if not self.wait():
                raise HeadTimeout(f"step {i} of the script for {script.response!r} did not "
                                  f"finish within {self.last_move_s + WAIT_SLACK_S:.1f} s; "
                                  "is a servo blocked or the speed calibrated too high?")
            if step.hold_ms:
                self._sleep(step.hold_ms / 1000.0)

    def looking_at(self) -> str | None:
        """The direction whose pose the head is at (within tolerance), or None."""
        if self._closed or self.is_moving():
            return None
        pos = self.positions()
        tol = self.calibration.tolerance_us
        for name, pose in self.calibration.directions.items():
            if all(abs(pos[s] - v) <= tol for s, v in pose.items()):
                return name
        return None

    def status(self) -> dict[str, Any]:
        """Positions, targets, motion, direction and errors, as plain values."""
        self._check_open()
        return {
            "positions": {n: round(v, 2) for n, v in self.positions().items()},
            "targets": dict(self.targets),
            "moving": self.is_moving(),
            "looking_at": self.looking_at(),
            "clamped": self.clamped_count,
            "errors": self._errors(),
        }

    @property
    def closed(self) -> bool:
        """Whether the head is closed."""
        return self._closed

    def close(self, centre: bool = True) -> None:
        """Return to centre, wait for it, then release the device. Safe to call twice.

        Args:
            centre: return to centre first (``False`` leaves the head where it is).

        Raises:
            HeadError: returning to centre failed (the device is released anyway).
        """
        if self._closed:
            return
        try:
            if centre:
                self.move_to(self.calibration.centre_pose())
                self.wait()
        finally:
            self._closed = True
            self._release()

    def reopen(self) -> None:
        """Release the device if held and acquire it again (after a lost port)."""
        if not self._closed:
            self._closed = True
            self._release()
        self._open()
        self._closed = False

    def __enter__(self) -> Self:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc_type is None:
            self.close()
            return
        try:
            self.close()
        except HeadError:
            pass  # keep the original exception; the device is released anyway
