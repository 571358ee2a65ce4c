"""What a session shows and keeps of every time unit: the extended trace, recorded frames,
the tree over time, and the live monitor's feed.

:class:`SessionTap` is the one hook the session calls per time unit. It builds a
:class:`~relrl.monitor.view.StepView` (percepts, working memory with ages, necessities,
reward, response and explanation, the head's commanded pose, running CGI and eye contacts,
what perception found in the frame) when someone needs it -- every unit for the trace
(``--out``), at the monitor's rate for the browser -- and otherwise only hands the necessity
outputs to the monitor's plot.

A recorded session (``--out DIR --record``) is a self-contained folder::

    session.json     what was run: episode, learner, devices, rates, the files below
    episode.toml     the script, its domain path pointing at domain.pl
    domain.pl        the domain
    trace.jsonl      one StepView per time unit (the frame index when one was recorded)
    frames/          JPEG frames, 000001.jpg ... (``--record-rate`` per second at most;
                     0: every time unit, which ``--camera DIR`` can perceive again)
    frames.jsonl     one line per frame: index, time unit, file, where the head looked
    trees.jsonl      the learner's tree whenever it changed (checked once a second)
    events.jsonl     evaluations and naming executions as they happened
    summary.json, timing.json, policy, plots, run.log

``relrl replay DIR`` serves the monitor's page over it.
"""

from __future__ import annotations

import json
import queue
import re
import threading
import time
from pathlib import Path
from typing import Any

from relrl.episodes.provenance import provenance
from relrl.errors import OutputError
from relrl.monitor.view import head_view, metrics_view, overlay_of, view_of
from relrl.outdir import open_stream, write_atomic, write_json_atomic

__all__ = ["FrameRecorder", "RECORDED", "SessionTap", "write_manifest"]

#: the files and folders a recorded session writes besides the summary's (``--record``).
RECORDED = ("session.json", "episode.toml", "domain.pl", "trees.jsonl", "events.jsonl",
            "frames.jsonl", "frames/")

#: what a traced or shown step asks the engine for, in the step's one gateway call.
WANTS = ("memory", "explain")
#: seconds between checks of whether the learner's tree changed.
TREE_PERIOD = 1.0


class FrameRecorder:
    """JPEG frames written by a thread of their own (the control loop only queues them).

    Every frame is a whole file written through :func:`relrl.outdir.write_atomic` (never
    through a link: a ``frames`` that is a link is refused). A frame that cannot be written
    (a full disk) stops the session at its next frame.

    Args:
        folder: the session folder (frames go to ``folder/frames``).
        rate: frames per second at most; 0 records every frame given.
        quality: JPEG quality, 1..100.
    """

    def __init__(self, folder: Path, rate: float = 10.0, quality: int = 85) -> None:
        self.folder = folder
        self.rate, self.quality = float(rate), int(quality)
        self.count = 0
        self.bytes = 0
        self._next = 0.0
        self._index = open_stream(folder / "frames.jsonl")
        self._queue: queue.Queue[tuple[Path, Any] | None] = queue.Queue(maxsize=64)
        self._thread = threading.Thread(target=self._write, name="relrl-frames", daemon=True)
        self._thread.start()
        self._error: BaseException | None = None

    def due(self) -> bool:
        """Whether a frame is to be recorded now."""
        return self.rate <= 0 or time.perf_counter() >= self._next

    def add(self, frame: Any, t: int, looking_at: str | None) -> int:
        """Queue a frame of time unit ``t``; returns its index (from 1)."""
        self.check()
        self.count += 1
        name = f"{self.count:06d}.jpg"
        self._queue.put((self.folder / "frames" / name, frame))  # waits when 64 are queued
        self._index.write(json.dumps({"index": self.count, "t": t, "file": f"frames/{name}",
                                      "looking_at": looking_at}) + "\n")
        if self.rate > 0:
            self._next = time.perf_counter() + 1.0 / self.rate
        return self.count

    def _write(self) -> None:
        from relrl.monitor.frames import encode_jpeg

        while (item := self._queue.get()) is not None:
            path, frame = item
            if self._error is not None:
                continue  # the loop stops at its next frame; the rest are dropped
            try:
                data = encode_jpeg(frame, self.quality)
                write_atomic(path, data, spare=False)
                self.bytes += len(data)
            except (OutputError, OSError, ValueError) as exc:  # disk full, ...: raised in
                self._error = exc                               # the loop

    def check(self) -> None:
        """Raise the error that stopped a frame from being written, if one did."""
        if self._error is not None:
            raise self._error

    def close(self) -> None:
        """Write every queued frame and close the index (safe twice)."""
        if not self._index.closed:
            self._queue.put(None)
            self._thread.join()
            self._index.close()


def _copy_script(episode: Any, folder: Path) -> dict[str, str]:
    """Copy the script and its domain into the folder; the copy names ``domain.pl``."""
    files = {}
    domain = Path(episode.domain)
    if domain.is_file():
        write_atomic(folder / "domain.pl", domain.read_bytes())
        files["domain"] = "domain.pl"
    script = Path(episode.path) if getattr(episode, "path", None) else None
    if script is not None and script.is_file():
        text = script.read_text(encoding="utf-8")
        if "domain" in files:
            text = re.sub(r'(?m)^(\s*domain\s*=\s*)(["\']).*?\2', r'\g<1>"domain.pl"', text,
                          count=1)
        write_atomic(folder / "episode.toml", text)
        files["script"] = "episode.toml"
    return files


def write_manifest(folder: Path, data: dict[str, Any]) -> None:
    """Write ``session.json`` (atomic)."""
    write_json_atomic(folder / "session.json", data)


class SessionTap:
    """The per-time-unit hook of a session: trace, frames, trees, events, monitor.

    Args:
        run: the session's run state (knowledge base, learner, metrics).
        out: the output folder, or ``None``.
        env: the session's world (its ``last_frame`` / ``last_percept`` when it has them).
        head: the :class:`head.Head` the responses go to, or ``None``.
        hub: the live monitor's :class:`~relrl.monitor.hub.Hub`, or ``None``.
        record: record frames, trees and events into ``out``.
        record_rate: frames per second at most (0: every time unit).
        record_quality: JPEG quality.
    """

    def __init__(self, run: Any, out: Path | None, env: Any, head: Any = None, *,
                 hub: Any = None, record: bool = False, record_rate: float = 10.0,
                 record_quality: int = 85) -> None:
        self.run, self.out, self.env, self.head, self.hub = run, out, env, head, hub
        recording = record and out is not None
        self.trace = self.frames = self._trees = self._events = None
        try:
            self.trace = open_stream(out / "trace.jsonl") if out is not None else None
            self.frames = FrameRecorder(out, record_rate, record_quality) if recording \
                else None
            self._trees = open_stream(out / "trees.jsonl") if recording else None
            self._events = open_stream(out / "events.jsonl") if recording else None
            self.files: dict[str, str] = _copy_script(run.episode, out) if recording else {}
        except BaseException:
            self.close()
            raise
        self._tree_key: Any = None
        self._tree_graph: dict[str, Any] | None = None
        self._tree_next = 0.0
        self._seen: tuple[Any, Any, Any] = (None, None, None)
        self._asked = False
        if hub is not None:
            from relrl.terms import format_term

            ep = run.episode
            hub.info.update({
                "episode": ep.name, "learner": ep.learner, "seed": ep.seed,
                "steps": ep.steps, "perception": ep.perception,
                "necessities": run.agent.necessities,
                "responses": [format_term(r) for r in run.agent.responses],
                "where": {k: v for k, v in provenance(run.opts).items()
                          if not k.endswith("_label")},
            })

    def start(self) -> None:
        """The world has been reset: remember the first frame it perceived."""
        self._seen = self._now_seen()
        self._tree(0, force=True)

    def _now_seen(self) -> tuple[Any, Any, Any]:
        """The world's last frame, what perception found in it and where the head looked."""
        env = self.env
        return (getattr(env, "last_frame", None), getattr(env, "last_percept", None),
                getattr(env, "focus", None))

    def want(self) -> tuple[str, ...]:
        """What the next step is to report from its one gateway call: working memory and
        the explanation when this time unit is traced or shown, nothing otherwise."""
        self._asked = self.trace is not None or (self.hub is not None and self.hub.due())
        return WANTS if self._asked else ()

    def step(self, record: Any, phase: str, *, outcome: str | None = None,
             said: str | None = None) -> dict[str, Any] | None:
        """One time unit: returns the trace row when one was built."""
        run, hub = self.run, self.hub
        out = record.out
        frame, percept, looked = self._seen  # what this step's percepts came from
        self._seen = self._now_seen()
        if hub is not None:
            hub.tick(run.t, list(out.outputs.values()), float(out.reward))
        if not self._asked:  # neither traced nor shown: the plot's point is all
            return None
        self._asked = False
        publish = hub is not None and hub.due()
        info = record.info
        view = view_of(run.t, phase, record)
        view.head = head_view(self.head, info["record"].focus)
        view.metrics = metrics_view(run.metrics)
        view.extra = {"unit": info.get("unit", run.t),  # the time unit this step belongs to
                      "caregiver": info.get("scene"), "focus": info["record"].focus,
                      "heard": info["words"], "naming": outcome, "said": said,
                      "overlay": overlay_of(percept, frame)}
        if self.frames is not None and frame is not None and self.frames.due():
            view.extra["frame"] = self.frames.add(frame, run.t, looked)
        row = view.row()
        if self.trace is not None:
            self.trace.write(json.dumps(row, sort_keys=True) + "\n")
            self.trace.flush()
        if publish:
            hub.publish(dict(row), frame)
        self._tree(run.t)
        return row

    def _tree(self, t: int, force: bool = False) -> None:
        if self.hub is None and self._trees is None:
            return
        now = time.perf_counter()
        if not force and now < self._tree_next:
            return
        self._tree_next = now + TREE_PERIOD
        from relrl.monitor.graph import shown_graph

        graph = shown_graph(self.run.learner, self._tree_graph)
        self._tree_graph = graph
        key = json.dumps(graph, sort_keys=True)
        if key == self._tree_key:
            return
        self._tree_key = key
        if self.hub is not None:
            self.hub.set_tree(graph)
        if self._trees is not None:
            self._trees.write(json.dumps({"t": t, "graph": graph}) + "\n")
            self._trees.flush()

    def event(self, kind: str, **data: Any) -> None:
        """A session event (evaluation, naming execution) for the monitor and the recording."""
        if self.hub is not None:
            self.hub.event(kind, t=self.run.t, **data)
        if self._events is not None:
            self._events.write(json.dumps({"kind": kind, "t": self.run.t, **data},
                                          default=str) + "\n")
            self._events.flush()

    def finish(self) -> dict[str, Any]:
        """The session ended: the last tree, the last frame (when every unit is recorded).

        Returns:
            what was recorded (frames, bytes), for ``session.json``.
        """
        self._tree(self.run.t, force=True)
        frame, _, looked = self._seen
        if self.frames is not None and self.frames.rate <= 0 and frame is not None:
            self.frames.add(frame, self.run.t + 1, looked)
        if self.hub is not None:
            self.hub.finish()
        stats = self.close()
        if self.frames is not None:
            self.frames.check()  # the last frames were written, or the run says why not
        return stats

    def close(self) -> dict[str, Any]:
        """Flush and close every file (safe twice); returns the recording's figures."""
        stats: dict[str, Any] = {}
        if self.frames is not None:
            self.frames.close()
            stats = {"frames": self.frames.count, "frame_bytes": self.frames.bytes,
                     "record_rate": self.frames.rate, "jpeg_quality": self.frames.quality}
        for fh in (self.trace, self._trees, self._events):
            if fh is not None and not fh.closed:
                fh.close()
        return stats
