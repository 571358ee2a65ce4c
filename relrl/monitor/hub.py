"""The live side of the monitor: what the control loop hands over, and at what rate.

The control loop runs in the main thread (it alone may call Prolog); the web server runs in
a process of its own (:mod:`relrl.monitor.live`). They meet here, and the loop never waits
for the server:

* every time unit the loop adds one point to the necessity series (:meth:`Hub.tick`: a
  lock and a list append);
* at most ``rate`` times a second (:meth:`Hub.due`) it publishes a full
  :class:`~relrl.monitor.view.StepView` with a reference to the camera frame
  (:meth:`Hub.publish`); views in between are never built;
* the server reads the newest view when it sends; a browser that is slow only ever gets the
  newest one, so views and frames in between are dropped, never queued;
* what the session is doing (:meth:`Hub.status`: starting, waiting for the camera, the
  initial evaluation, learning, evaluating, naming, saving, finished) is handed over when it
  changes, so the page says it from the session's own state -- before the first time unit
  too, when there is no view yet.

Frames are JPEG-encoded once per published frame, by the thread that hands them to the web
server's process (:mod:`relrl.monitor.live`). There a second hub, fed with
:meth:`Hub.changes` and :meth:`Hub.apply`, answers the browsers; the robot's process holds
none of their connections.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from typing import Any

__all__ = ["ACTIVITIES", "Hub"]

#: points of the necessity series kept for a browser that connects late.
SERIES_KEEP = 2000
#: points sent in one message at most (the newest; the page plots the last 600).
SERIES_SEND = 600
#: what a session can be doing, as :meth:`Hub.status` and the page's status line name it.
ACTIVITIES = ("starting", "waiting for the camera", "initial evaluation", "learning",
              "acting", "evaluating", "naming", "saving", "finished", "stopped")


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
        self.state: dict[str, Any] | None = None
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

    def status(self, activity: str, detail: str = "", **data: Any) -> None:
        """What the session is doing now (called when that changes, not every time unit).

        Args:
            activity: one of :data:`ACTIVITIES`.
            detail: one sentence for the page (what, on what, how long).
            data: JSON-ready facts the page shows as progress: ``done`` and ``total`` (runs
                of an evaluation, executions of naming), ``phase``, ``steps``.

        Raises:
            ValueError: an activity that is not one of :data:`ACTIVITIES`.
        """
        if activity not in ACTIVITIES:
            raise ValueError(f"unknown activity {activity!r} (one of {', '.join(ACTIVITIES)})")
        with self._lock:
            self.state = {"activity": activity, "detail": detail, **data}
            self.version += 1

    def finish(self) -> None:
        """The session has ended (the page says so)."""
        with self._lock:
            self.finished = True
            self.version += 1

    # -- the server's side ----------------------------------------------------------------

    def message(self, version: int, series_count: int, *, keep: int = SERIES_SEND
                ) -> tuple[dict[str, Any] | None, int, int]:
        """What is new since ``version`` and ``series_count`` (``None`` when nothing), with at
        most the ``keep`` newest points of the series.

        Returns:
            the message, the version and the series count it brings the reader to.
        """
        with self._lock:
            if version == self.version and series_count == self._series_count:
                return None, version, series_count
            points = list(self._series)  # one atomic copy
            count = points[-1][0] if points else 0
            series = [[t, ys, r] for n, t, ys, r in points[-keep:] if n > series_count]
            msg = {"info": {"rate": self.rate, **self.info}, "view": self.view,
                   "series": series, "tree_version": self.tree_version,
                   "events": list(self.events), "status": self.state,
                   "finished": self.finished}
            return msg, self.version, count

    def jpeg(self, quality: int = 80) -> tuple[int, bytes] | None:
        """The newest frame as JPEG bytes with its sequence number (encoded once)."""
        with self._lock:
            frame, seq, cached = self.frame, self.frame_seq, self._jpeg
        if cached is not None and cached[0] == seq:
            return cached
        if frame is None:
            return None
        from relrl.monitor.frames import encode_jpeg

        self._jpeg = (seq, encode_jpeg(frame, quality))
        return self._jpeg

    def tree_state(self) -> tuple[int, dict[str, Any] | None]:
        """The tree's version and the tree (one consistent pair)."""
        with self._lock:
            return self.tree_version, self.tree

    # -- handing over to another process (relrl.monitor.live) ----------------------------

    def changes(self, mark: dict[str, int]) -> dict[str, Any] | None:
        """What changed since ``mark`` (updated in place; start with ``{}``) as plain data
        for :meth:`apply`: the message (every new point of the series the hub keeps), the
        tree when it changed, the newest frame as JPEG when it changed. ``None``: nothing."""
        update: dict[str, Any] = {}
        msg, mark["version"], mark["count"] = self.message(
            mark.get("version", -1), mark.get("count", 0), keep=SERIES_KEEP)
        if msg is not None:
            update["message"] = msg
        tree_version, tree = self.tree_state()
        if tree_version != mark.get("tree", -1):
            update["tree"], mark["tree"] = (tree_version, tree), tree_version
        got = self.jpeg()
        if got is not None and got[0] != mark.get("frame", -1):
            update["jpeg"], mark["frame"] = got, got[0]
        return update or None

    def apply(self, update: dict[str, Any]) -> None:
        """Take over what another hub's :meth:`changes` gave."""
        msg = update.get("message")
        with self._lock:
            if msg is not None:
                self.info = {k: v for k, v in (msg.get("info") or {}).items() if k != "rate"}
                self.view = msg.get("view")
                for t, ys, r in msg.get("series") or ():
                    self._series_count += 1
                    self._series.append((self._series_count, t, ys, r))
                self.events = list(msg.get("events") or ())
                self.state = msg.get("status")
                self.finished = bool(msg.get("finished"))
            if "tree" in update:
                self.tree_version, self.tree = update["tree"]
            if "jpeg" in update:
                self._jpeg = tuple(update["jpeg"])  # type: ignore[assignment]
                self.frame_seq = self._jpeg[0]
            self.version += 1
