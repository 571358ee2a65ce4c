"""The simulated head: servo positions that move at the calibrated speed in simulated time.

Time only passes when :meth:`SimHead.tick` is called (``wait`` and script pauses call it), so
tests are fast and deterministic. Pass ``realtime=True`` to also sleep for real, for demos.
Every move start and end is recorded in :attr:`SimHead.events` (and given to ``on_event``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from head.base import Head, MotionModel
from head.calibration import Calibration, load_calibration

__all__ = ["HeadEvent", "SimHead"]


@dataclass(frozen=True)
class HeadEvent:
    """Something the simulated head did.

    Attributes:
        time: simulated seconds since the head was opened.
        kind: ``"move"`` (a move started) or ``"arrived"`` (the move ended).
        pose: the target pose of the move.
        direction: for ``arrived``, the direction the head now looks at (or None).
    """

    time: float
    kind: str
    pose: dict[str, int]
    direction: str | None = None


class SimHead(Head):
    """A head with no hardware, built from the same calibration as the real one."""

    def __init__(self, calibration: Calibration | None = None, *, realtime: bool = False,
                 on_event: Callable[[HeadEvent], None] | None = None) -> None:
        super().__init__(calibration or load_calibration())
        self.realtime = realtime
        self.on_event = on_event
        self.events: list[HeadEvent] = []
        self.time = 0.0
        self._model = MotionModel({n: float(v) for n, v in self.targets.items()})
        self._pending_end: float | None = None
        self._open()
        self._closed = False

    def _open(self) -> None:
        self._pending_end = None

    def _release(self) -> None:
        self._pending_end = None

    def _emit_event(self, event: HeadEvent) -> None:
        self.events.append(event)
        if self.on_event is not None:
            self.on_event(event)

    def _command(self, pose: dict[str, int], speeds: dict[str, float]) -> float:
        duration = self._model.command(self.time, pose, speeds)
        self._emit_event(HeadEvent(self.time, "move", dict(pose)))
        self._pending_end = self.time + duration
        self._settle()
        return duration

    def _settle(self) -> None:
        """Record the end of the current move once simulated time reaches it."""
        if self._pending_end is not None and self.time >= self._pending_end:
            end, self._pending_end = self._pending_end, None
            self._emit_event(HeadEvent(end, "arrived", dict(self.targets), self.looking_at()))

    def tick(self, dt: float) -> None:
        """Advance simulated time by ``dt`` seconds."""
        if dt < 0:
            raise ValueError(f"tick({dt}) cannot go back in time")
        self.time += dt
        if self.realtime:
            time.sleep(dt)
        self._settle()

    def positions(self) -> dict[str, float]:
        """Servo positions at the current simulated time."""
        return self._model.at(self.time)

    def is_moving(self) -> bool:
        """Whether the current move has not ended at the current simulated time."""
        return self._model.moving(self.time)

    def _now(self) -> float:
        return self.time

    def _sleep(self, seconds: float) -> None:
        self.tick(seconds)

    def wait(self, timeout: float | None = None) -> bool:
        """Jump simulated time to the end of the move (or the timeout, if sooner)."""
        self._check_open()
        end = self._model.end_time()
        if end <= self.time:
            return True
        limit = self.last_move_s + 1.0 if timeout is None else timeout
        self.tick(min(end - self.time, max(0.0, limit)))
        return not self.is_moving()
