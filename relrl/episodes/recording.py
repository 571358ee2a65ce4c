"""What a session shows and keeps of every time unit: the extended trace, the recording, and
the live monitor's and Foxglove's feeds.

:class:`SessionTap` is the one hook the session calls per time unit. It builds a
:class:`~relrl.monitor.view.StepView` (percepts, working memory with ages, necessities,
reward, response and explanation, the head's commanded pose, running CGI and eye contacts,
what perception found in the frame) when someone needs it -- every unit for the trace
(``--out``) and the recording, at the monitor's rate for the browser and a live Foxglove --
and otherwise only hands the necessity outputs to the monitor's plot.

A recorded session (``--out DIR --record``) is one MCAP file beside the run's outputs::

    session.mcap     every channel of the session (relrl.recording.channels): the camera as
                     ROS 2 CompressedImage with Foxglove annotations, the head's joint
                     states, percepts, working memory, necessities, reward, response and
                     explanation, the tree whenever it changed, evaluations and naming; the
                     script and domain attached, session.json and summary.json as metadata
    session.json     what was run: episode, learner, devices, rates, the files
    episode.toml     the script, its domain path pointing at domain.pl
    domain.pl        the domain
    trace.jsonl      one StepView per time unit (``--out``; the frame index when one was
                     recorded)
    events.out.tfevents.relrl
                     the time units' scalars for TensorBoard (``--out``: reward, the
                     necessity units' outputs, running CGI, eye contacts, working memory;
                     each evaluation's CGI, each naming execution's outcomes)
    summary.json, timing.json, policy, plots, run.log

``relrl replay DIR`` (or ``relrl replay DIR/session.mcap``) serves the monitor's page over
it; Foxglove opens ``session.mcap``. Frames are recorded at ``--record-rate`` per second at
most (0: every time unit, which ``--camera DIR`` can perceive again).
"""

from __future__ import annotations

import json
import re
import time
from pathlib import Path
from typing import Any

from relrl.episodes.provenance import provenance
from relrl.monitor.tap import TreeWatch, leaf_of
from relrl.monitor.view import head_view, metrics_view, overlay_of, view_of
from relrl.outdir import open_stream, write_atomic, write_json_atomic
from relrl.tensorboard import EVENT_FILE, ScalarLog

__all__ = ["RECORDING", "SessionTap", "write_manifest"]

#: what a traced or shown step asks the engine for, in the step's one gateway call.
WANTS = ("memory", "explain")
#: seconds between checks of whether the learner's tree changed (and at once when a step's
#: leaf is not in the tree last sent: the tree has split).
TREE_PERIOD = 1.0
#: the recording's file in the session folder.
RECORDING = "session.mcap"


class _Rate:
    """At most ``rate`` a second (0: every time)."""

    def __init__(self, rate: float) -> None:
        self.rate = float(rate)
        self._next = 0.0

    def due(self) -> bool:
        return self.rate <= 0 or time.perf_counter() >= self._next

    def took(self) -> None:
        if self.rate > 0:
            self._next = time.perf_counter() + 1.0 / self.rate


def _scalars(row: dict[str, Any]) -> dict[str, Any]:
    """A trace row's numbers for TensorBoard (what is not a number is left out there)."""
    metrics = row.get("metrics") or {}
    return {"reward": row.get("reward"), "memory/working_memory": row.get("memory_size"),
            **{f"necessity/{k}": v for k, v in (row.get("activation") or {}).items()},
            **{f"gaze/{k}": metrics.get(k) for k in ("cgi", "shifts", "eye_contacts",
                                                     "opportunities")}}


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
    """The per-time-unit hook of a session: trace, recording, monitor, Foxglove.

    Args:
        run: the session's run state (knowledge base, learner, metrics).
        out: the output folder, or ``None``.
        env: the session's world (its ``last_frame`` / ``last_percept`` when it has them).
        head: the :class:`head.Head` the responses go to, or ``None``.
        hub: the live monitor's :class:`~relrl.monitor.hub.Hub`, or ``None``.
        record: record the session into ``out/session.mcap``.
        record_rate: frames per second at most (0: every time unit).
        record_quality: JPEG quality.
        recorder: a started :class:`~relrl.recording.recorder.Recorder` (serving Foxglove),
            or ``None`` (one is started when recording).
        live_rate: time units (and frames) sent to Foxglove per second at most when the
            session is not recorded (a recorded session sends every unit it records).
    """

    def __init__(self, run: Any, out: Path | None, env: Any, head: Any = None, *,
                 hub: Any = None, record: bool = False, record_rate: float = 10.0,
                 record_quality: int = 85, recorder: Any = None,
                 live_rate: float = 10.0) -> None:
        self.run, self.out, self.env, self.head, self.hub = run, out, env, head, hub
        self.trace = None
        self.scalars: ScalarLog | None = None
        self.recording = record and out is not None
        self.recorder, self._own = recorder, False
        self.quality = int(record_quality)
        self.frames = 0
        self.traced = 0  # trace lines written
        self._frame_rate = _Rate(record_rate if self.recording else live_rate)
        self._live = _Rate(0 if self.recording else live_rate)  # units sent when live only
        self.files: dict[str, str] = {}
        try:
            self.trace = open_stream(out / "trace.jsonl") if out is not None else None
            self.scalars = ScalarLog(out / EVENT_FILE) if out is not None else None
            if self.recording:
                if self.recorder is None:
                    from relrl.recording.recorder import Recorder

                    self.recorder, self._own = Recorder(), True
                # the file is made (journalled, never through a link) by the one writer;
                # the recorder's own process then fills it
                open_stream(out / RECORDING, binary=True).close()
                self.recorder.open(out / RECORDING)
                self.files = _copy_script(run.episode, out)
                self.files["recording"] = RECORDING
                for name in ("episode.toml", "domain.pl"):
                    if (out / name).is_file():
                        self.recorder.attach(name, "text/plain", (out / name).read_bytes())
        except BaseException:
            self.close()
            raise
        self.tree = TreeWatch(run.learner, TREE_PERIOD)
        self._seen: tuple[Any, Any, Any] = (None, None, None)
        self._asked = False
        from relrl.terms import format_term

        ep = run.episode
        self.info = {
            "episode": ep.name, "learner": ep.learner, "seed": ep.seed,
            "steps": ep.steps, "perception": ep.perception,
            "necessities": run.agent.necessities,
            "responses": [format_term(r) for r in run.agent.responses],
            "where": {k: v for k, v in provenance(run.opts).items()
                      if not k.endswith("_label")},
        }
        if hub is not None:
            hub.info.update(self.info)
        if self.recorder is not None:
            self.recorder.session(self.info)

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
        self._asked = (self.trace is not None or (self.hub is not None and self.hub.due())
                       or (self.recorder is not None and self._live.due()))
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
        framed = None
        if self.recorder is not None and frame is not None and self._frame_rate.due():
            self._frame_rate.took()
            self.frames += 1
            view.extra["frame"] = self.frames
            view.extra["frame_looking_at"] = looked  # where the head was when it was seen
            framed = frame
        row = view.row()
        sent = self.recorder is not None and (framed is not None or self._live.due())
        line = json.dumps(row, sort_keys=True) if self.trace is not None or sent else ""
        if self.trace is not None:
            self.trace.write(line + "\n")
            self.trace.flush()
            self.traced += 1
            self.scalars.add(run.t, _scalars(row))
        if publish:
            hub.publish(dict(row), frame)
        if sent:  # the writer process encodes the channels from the line
            from relrl.monitor.frames import encode_jpeg

            self._live.took()
            self.recorder.unit(time.time_ns(), line.encode(),
                               encode_jpeg(framed, self.quality) if framed is not None
                               else None)
        self._tree(run.t, leaf_of(view.explanation, view.response))
        return row

    def _tree(self, t: int, leaf: str | None = None, force: bool = False) -> None:
        """The learner's tree to the monitor and the recording when it changed."""
        if (self.hub is None and self.recorder is None) or \
                not self.tree.changed(leaf, force=force):
            return
        if self.hub is not None:
            self.hub.set_tree(self.tree.graph)
        if self.recorder is not None:
            self.recorder.tree(t, self.tree.graph)

    def event(self, kind: str, **data: Any) -> None:
        """A session event (evaluation, naming execution) for the monitor, the recording and
        TensorBoard (an evaluation at its time unit, a naming execution at its number)."""
        if self.scalars is not None:
            if kind == "evaluation":
                self.scalars.add(self.run.t, {"evaluation/cgi_mean": data.get("cgi_mean"),
                                              "evaluation/cgi_std": data.get("cgi_std")})
            elif kind == "naming":
                self.scalars.add(data.get("execution", 0), {
                    f"naming/{k}": v for k, v in (data.get("counts") or {}).items()})
        if self.hub is not None:
            self.hub.event(kind, t=self.run.t, **data)
        if self.recorder is not None:
            self.recorder.event(kind, self.run.t, **data)

    def finish(self) -> dict[str, Any]:
        """The session ended: the last tree, the last frame (when every unit is recorded);
        TensorBoard's event file written out and closed (here, while the session's own
        errors and signals are still handled, not in the clean-up after them).

        Returns:
            what was recorded (frames, bytes), for ``session.json``.
        """
        if self.scalars is not None:
            self.scalars.close()
        self._tree(self.run.t, force=True)
        frame, percept, looked = self._seen
        if self.recording and self._frame_rate.rate <= 0 and frame is not None:
            from relrl.monitor.frames import encode_jpeg

            self.frames += 1
            self.recorder.last_frame(time.time_ns(), {
                "t": self.run.t + 1, "overlay": overlay_of(percept, frame),
                "frame": self.frames, "frame_looking_at": looked},
                encode_jpeg(frame, self.quality))
        if self.hub is not None:
            self.hub.finish()
        if not self.recording:
            return {}
        return {**self.recorder.stats(), "record_rate": self._frame_rate.rate,
                "jpeg_quality": self.quality, "file": RECORDING}

    def close(self, manifest: dict[str, Any] | None = None,
              summary: dict[str, Any] | None = None) -> None:
        """Close the recording -- with what was run and its summary in it, when given --
        the trace and TensorBoard's event file (safe twice)."""
        try:
            if self.recording and self.recorder is not None:
                self.recorder.close_file({name: value for name, value in (
                    ("relrl.session", manifest), ("relrl.summary", summary)) if value})
        finally:
            if self._own:
                self.recorder.close()
            if self.trace is not None and not self.trace.closed:
                self.trace.close()
            if self.scalars is not None:
                self.scalars.close()
