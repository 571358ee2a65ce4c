"""The live side of the monitor: what the control loop hands over, and at what rate.

The control loop runs in the main thread (it alone may call Prolog); the web server runs in
a thread of its own. They meet here, and the loop never waits for the server:

* every time unit the loop adds one point to the necessity series (:meth:`Hub.tick`: a
  lock and a list append);
* at most ``rate`` times a second (:meth:`Hub.due`) it publishes a full
  :class:`~relrl.monitor.view.StepView` with a reference to the camera frame
  (:meth:`Hub.publish`); views in between are never built;
* the server reads the newest view when it sends; a browser that is slow only ever gets the
  newest one, so views and frames in between are dropped, never queued.

Frames are JPEG-encoded by the server thread, once per published frame, when a browser asks.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from typing import Any

__all__ = ["Hub"]

#: points of the necessity series kept for a browser that connects late.
SERIES_KEEP = 2000
#: points sent in one message at most (the newest; the page plots the last 600).
SERIES_SEND = 600


class Hub:
    """The monitor's shared state between the control loop and the web server.

    Args:
        rate: views (and frames) handed to the browser per second, at most.
        info: what does not change during the session (episode, learner, necessities,
            devices, labels); shown in the page's header.
    """

    def __init__(self, rate: float = 10.0, info: dict[str, Any] | None = None) -> None:
        if not rate > 0:
            raise ValueError(f"the monitor's rate must be positive, not {rate}")
        self.rate = float(rate)
        self.period = 1.0 / self.rate
        self.info: dict[str, Any] = dict(info or {})
        self._lock = threading.Lock()
        self._next = 0.0
        self._series: deque[list[Any]] = deque(maxlen=SERIES_KEEP)
        self._series_count = 0
        self.version = 0
        self.view: dict[str, Any] | None = None
        self.frame: Any = None
        self.frame_seq = 0
        self.tree: dict[str, Any] | None = None
        self.tree_version = 0
        self.events: list[dict[str, Any]] = []
        self.finished = False
        self._jpeg: tuple[int, bytes] | None = None

    # -- the control loop's side (cheap) --------------------------------------------------

    def due(self) -> bool:
        """Whether a full view is wanted now (at most :attr:`rate` a second)."""
        return time.perf_counter() >= self._next

    def tick(self, t: int, activation: list[float], reward: float) -> None:
        """One time unit's necessity outputs and reward (every unit; kept for the plot).

        No lock: only the control loop appends, and a deque's append (like the reader's
        copy of it) is atomic under the GIL."""
        n = self._series_count + 1
        self._series.append((n, t, activation, reward))
        self._series_count = n

    def publish(self, view: dict[str, Any], frame: Any = None) -> None:
        """Hand over the newest view (a :meth:`StepView.row`) and its camera frame."""
        with self._lock:
            self.view = view
            if frame is not None:
                self.frame = frame
                self.frame_seq += 1
                view["frame_seq"] = self.frame_seq
            else:
                view["frame_seq"] = self.frame_seq if self.frame is not None else None
            self.version += 1
        self._next = time.perf_counter() + self.period

    def set_tree(self, graph: dict[str, Any] | None) -> None:
        """Hand over the learner's tree (``{"nodes", "edges"}``) when it changed."""
        with self._lock:
            self.tree = graph
            self.tree_version += 1

    def event(self, kind: str, **data: Any) -> None:
        """A session event (an evaluation, a naming execution, the end)."""
        with self._lock:
            self.events.append({"kind": kind, **data})
            self.version += 1

    def finish(self) -> None:
        """The session has ended (the page says so)."""
        with self._lock:
            self.finished = True
            self.version += 1

    # -- the server's side ----------------------------------------------------------------

    def message(self, version: int, series_count: int) -> tuple[dict[str, Any] | None, int, int]:
        """What is new since ``version`` and ``series_count`` (``None`` when nothing).

        Returns:
            the message, the version and the series count it brings the reader to.
        """
        with self._lock:
            if version == self.version and series_count == self._series_count:
                return None, version, series_count
            points = list(self._series)  # one atomic copy
            count = points[-1][0] if points else 0
            series = [[t, ys, r] for n, t, ys, r in points[-SERIES_SEND:] if n > series_count]
            msg = {"info": {"rate": self.rate, **self.info}, "view": self.view,
                   "series": series, "tree_version": self.tree_version,
                   "events": list(self.events), "finished": self.finished}
            return msg, self.version, count

    def jpeg(self, quality: int = 80) -> tuple[int, bytes] | None:
        """The newest frame as JPEG bytes with its sequence number (encoded once)."""
        with self._lock:
            frame, seq = self.frame, self.frame_seq
        if frame is None:
            return None
        cached = self._jpeg
        if cached is not None and cached[0] == seq:
            return cached
        from relrl.monitor.frames import encode_jpeg

        self._jpeg = (seq, encode_jpeg(frame, quality))
        return self._jpeg
