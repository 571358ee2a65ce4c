"""A session's channels encoded off the control loop and handed to their sinks.

The control loop only queues what a time unit produced (:meth:`SessionStream.step`: the
trace row it built anyway, and a reference to the camera frame when one is to be recorded);
a thread of its own splits the row into the typed channels of
:mod:`relrl.recording.channels`, encodes them (JSON, ROS 2 CDR, the frame as JPEG with its
annotations) and hands every message to each sink: the MCAP file
(:class:`~relrl.recording.mcapfile.McapFile`), the live Foxglove server
(:class:`~relrl.monitor.foxglove.FoxgloveServer`), or both. One clock for all of it: the
wall clock in nanoseconds, read once per time unit by the loop.

The queue is bounded (:data:`QUEUE`): a disk slower than the session makes the loop wait
rather than lose a time unit of the file. An error of a sink (disk full) is raised in the
loop at its next call; the live server's sink never raises and never waits.
"""

from __future__ import annotations

import json
import math
import queue
import threading
import time
from typing import Any, Protocol

from relrl.recording.channels import (
    ANNOTATIONS,
    EVENTS,
    IMAGE,
    JOINTS,
    PERCEPTION,
    SESSION,
    TREE,
    Channel,
    annotations_of,
    cdr_encoders,
    joint_state_of,
    split_row,
)

__all__ = ["QUEUE", "SessionStream", "Sink"]

#: items (time units, frames, trees, events) queued for the encoding thread at most.
QUEUE = 256


class Sink(Protocol):
    """Where encoded messages go: ``write(channel, log_time_ns, data)``, ``close()``."""

    def write(self, channel: Channel, log_time: int, data: bytes) -> None: ...

    def close(self) -> Any: ...


def _finite(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def to_json(msg: dict[str, Any]) -> bytes:
    """A message as compact JSON bytes (non-finite numbers as ``null``: JSON has none)."""
    try:
        return json.dumps(msg, separators=(",", ":"), allow_nan=False, default=str).encode()
    except ValueError:
        return json.dumps(_finite(msg), separators=(",", ":"), default=str).encode()


class SessionStream:
    """Encode a session's channels in a thread and write them to every sink.

    Args:
        sinks: the MCAP file and/or the live server.
        quality: JPEG quality of the frames, 1..100.
    """

    def __init__(self, sinks: list[Sink], *, quality: int = 85) -> None:
        self.sinks = list(sinks)
        self.quality = int(quality)
        self.frames = 0
        self.frame_bytes = 0
        self.units = 0
        self._cdr = cdr_encoders()
        self._queue: queue.Queue[tuple[Any, ...] | None] = queue.Queue(maxsize=QUEUE)
        self._error: BaseException | None = None
        self._closed = False
        self._thread = threading.Thread(target=self._run, name="relrl-record", daemon=True)
        self._thread.start()

    # -- the control loop's side ----------------------------------------------------------

    def _put(self, item: tuple[Any, ...]) -> None:
        if self._error is not None:
            error, self._error = self._error, None
            raise error
        self._queue.put(item)

    def session(self, info: dict[str, Any]) -> None:
        """What the session runs (episode, learner, necessities ...), once at the start."""
        self._put(("json", SESSION, time.time_ns(), dict(info)))

    def step(self, row: dict[str, Any], frame: Any = None) -> None:
        """One time unit's trace row and, when one is to be recorded, its camera frame (the
        row's ``overlay`` is what perception found in it)."""
        self._put(("step", time.time_ns(), row, frame))

    def frame(self, t: int, index: int, frame: Any, overlay: dict[str, Any] | None,
              looking_at: str | None = None) -> None:
        """A frame with no time unit of its own (the last one, after the last unit)."""
        self._put(("frame", time.time_ns(), t, index, frame, overlay, looking_at))

    def attach(self, name: str, media_type: str, data: bytes) -> None:
        """A file carried inside the recording (the sinks that keep files)."""
        self._put(("attach", name, media_type, data))

    def tree(self, t: int, graph: dict[str, Any] | None) -> None:
        """The learner's tree, when it changed."""
        self._put(("json", TREE, time.time_ns(), {"t": t, "graph": graph}))

    def event(self, kind: str, t: int, **data: Any) -> None:
        """An evaluation or a naming execution."""
        self._put(("json", EVENTS, time.time_ns(), {"kind": kind, "t": t, **data}))

    # -- the encoding thread --------------------------------------------------------------

    def _send(self, channel: Channel, ns: int, data: bytes) -> None:
        for sink in self.sinks:
            sink.write(channel, ns, data)

    def _encode_step(self, ns: int, row: dict[str, Any], frame: Any) -> None:
        self.units += 1
        for channel, msg in split_row(row):
            self._send(channel, ns, to_json(msg))
        head = row.get("head")
        if head:
            self._send(JOINTS, ns, self._cdr[JOINTS.topic](joint_state_of(head, ns)))
        if frame is not None:
            self._encode_frame(ns, frame, row.get("overlay"))

    def _encode_frame(self, ns: int, frame: Any, overlay: dict[str, Any] | None) -> None:
        from relrl.monitor.frames import encode_jpeg

        jpeg = encode_jpeg(frame, self.quality)
        stamp = {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}
        self._send(IMAGE, ns, self._cdr[IMAGE.topic](
            {"header": {"stamp": stamp, "frame_id": "camera"}, "format": "jpeg",
             "data": jpeg}))
        self._send(ANNOTATIONS, ns, to_json(annotations_of(overlay, ns)))
        self.frames += 1
        self.frame_bytes += len(jpeg)

    def _encode(self, item: tuple[Any, ...]) -> None:
        kind = item[0]
        if kind == "step":
            self._encode_step(*item[1:])
        elif kind == "frame":
            _, ns, t, index, frame, overlay, looked = item
            self._send(PERCEPTION, ns, to_json({"t": t, "overlay": overlay, "frame": index,
                                                "frame_looking_at": looked}))
            self._encode_frame(ns, frame, overlay)
        elif kind == "attach":
            for sink in self.sinks:
                if hasattr(sink, "add_attachment"):
                    sink.add_attachment(*item[1:])
        else:
            _, channel, ns, msg = item
            self._send(channel, ns, to_json(msg))

    def _run(self) -> None:
        while True:
            item = self._queue.get()
            try:
                if item is None:
                    return
                if self._error is None:  # after a sink failed: drain, the loop raises
                    self._encode(item)
            except Exception as exc:  # noqa: BLE001 - raised again in the control loop
                self._error = exc
            finally:
                self._queue.task_done()

    def stats(self) -> dict[str, Any]:
        """What was encoded: time units, frames, their bytes."""
        return {"units": self.units, "frames": self.frames, "frame_bytes": self.frame_bytes,
                "jpeg_quality": self.quality}

    def drain(self) -> dict[str, Any]:
        """Wait until everything queued is encoded and written; returns :meth:`stats`."""
        if not self._closed:
            self._queue.join()
        return self.stats()

    def close(self, metadata: dict[str, dict[str, Any]] | None = None) -> dict[str, Any]:
        """Encode what is queued, add ``metadata`` (name -> JSON-ready dict) to the sinks
        that keep it, close every sink (safe twice); returns :meth:`stats`."""
        if not self._closed:
            self._closed = True
            self._queue.put(None)
            self._thread.join()
            first: BaseException | None = self._error
            for sink in self.sinks:
                try:
                    if first is None and metadata and hasattr(sink, "add_metadata"):
                        for name, value in metadata.items():
                            sink.add_metadata(name, {"json": to_json(value).decode()})
                    sink.close()
                except Exception as exc:  # noqa: BLE001 - every sink is closed
                    first = first or exc
            self._error = None
            if first is not None:
                raise first
        return self.stats()
