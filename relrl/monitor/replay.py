"""A recorded session read back for ``relrl replay DIR`` (see :mod:`relrl.episodes.recording`).

:class:`Recording` reads the folder (trace, frame index, trees, events, summary) and never
writes to it; :class:`ReplaySource` answers the monitor's page for any time unit.
"""

from __future__ import annotations

import bisect
import json
import threading
from pathlib import Path
from typing import Any

from relrl.errors import UserError

__all__ = ["Recording", "ReplaySource"]


def _jsonl(path: Path) -> list[dict[str, Any]]:
    if not path.is_file():
        return []
    rows = []
    with open(path, encoding="utf-8") as fh:
        for n, line in enumerate(fh, 1):
            if not line.strip():
                continue
            try:
                rows.append(json.loads(line))
            except json.JSONDecodeError as exc:
                if n == 1 or fh.read().strip():  # only a cut last line is forgiven
                    raise UserError(f"{path}:{n}: not a JSON line ({exc.msg})") from None
    return rows


class Recording:
    """A session folder: ``trace.jsonl`` and, when recorded, frames, trees and events.

    Raises:
        UserError: no such folder, or no trace in it.
    """

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise UserError(f"{folder}: no such folder")
        if not (self.folder / "trace.jsonl").is_file():
            raise UserError(f"{folder}: not a recorded session (no trace.jsonl); record one "
                            "with relrl run EPISODE --out DIR --record")
        self.rows = _jsonl(self.folder / "trace.jsonl")
        if not self.rows:
            raise UserError(f"{folder}/trace.jsonl: the trace is empty")
        self.frames = _jsonl(self.folder / "frames.jsonl")
        self.trees = _jsonl(self.folder / "trees.jsonl")
        self.events = _jsonl(self.folder / "events.jsonl")
        self.manifest = self._json("session.json")
        self.summary = self._json("summary.json")
        self._t = [int(r["t"]) for r in self.rows]
        self._frame_t = [int(f["t"]) for f in self.frames]
        self._tree_t = [int(x["t"]) for x in self.trees]

    def _json(self, name: str) -> dict[str, Any]:
        path = self.folder / name
        if not path.is_file():
            return {}
        try:
            return json.loads(path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as exc:
            raise UserError(f"{path}:{exc.lineno}: not JSON ({exc.msg})") from None

    @property
    def necessities(self) -> list[str]:
        """The necessity units, in order."""
        return self.manifest.get("necessities") or list(self.rows[0].get("activation", {}))

    def row(self, t: int) -> dict[str, Any] | None:
        """The trace line of time unit ``t`` (``None`` outside the session)."""
        i = bisect.bisect_left(self._t, t)
        return self.rows[i] if i < len(self._t) and self._t[i] == t else None

    def frame_at(self, t: int) -> dict[str, Any] | None:
        """The newest recorded frame at or before time unit ``t``."""
        i = bisect.bisect_right(self._frame_t, t) - 1
        return self.frames[i] if i >= 0 else None

    def frame_bytes(self, index: int) -> bytes | None:
        """The JPEG bytes of recorded frame ``index`` (from 1)."""
        if not 1 <= index <= len(self.frames):
            return None
        path = self.folder / "frames" / f"{index:06d}.jpg"
        return path.read_bytes() if path.is_file() else None

    def tree_at(self, t: int) -> dict[str, Any] | None:
        """The learner's tree as it was at time unit ``t``."""
        i = bisect.bisect_right(self._tree_t, t) - 1
        return self.trees[i]["graph"] if i >= 0 else None


class ReplaySource:
    """What the monitor's page shows of a :class:`Recording`."""

    mode = "replay"
    period = 0.5

    def __init__(self, recording: Recording) -> None:
        self.rec = recording
        self._svg: dict[int, bytes | None] = {}
        self._lock = threading.Lock()

    def info(self) -> dict[str, Any]:
        rec, m = self.rec, self.rec.manifest
        return {"episode": m.get("episode", rec.summary.get("episode", rec.folder.name)),
                "learner": (m.get("learner") or {}).get("name",
                                                       (rec.summary.get("learner") or {})
                                                       .get("name")),
                "seed": m.get("seed"), "steps": len(rec.rows),
                "first": rec.rows[0]["t"], "last": rec.rows[-1]["t"],
                "necessities": rec.necessities, "responses": m.get("responses"),
                "perception": m.get("perception"), "where": m.get("where")
                or rec.summary.get("where"), "frames": len(rec.frames),
                "events": rec.events, "folder": str(rec.folder),
                "recording": m.get("recording")}

    def step(self, t: int) -> dict[str, Any] | None:
        row = self.rec.row(t)
        if row is None:
            return None
        out = dict(row)
        frame = self.rec.frame_at(t)
        out["frame_index"] = frame["index"] if frame else None
        out["frame_t"] = frame["t"] if frame else None
        seen = self.rec.row(frame["t"]) if frame else None
        out["overlay_of_frame"] = seen.get("overlay") if seen else None
        tree_i = bisect.bisect_right(self.rec._tree_t, t) - 1
        out["tree_version"] = tree_i
        return out

    def series(self) -> list[list[Any]]:
        names = self.rec.necessities
        return [[r["t"], [r.get("activation", {}).get(n, 0.0) for n in names],
                 r.get("reward", 0.0)] for r in self.rec.rows]

    def frame_jpeg(self, index: int) -> bytes | None:
        return self.rec.frame_bytes(index)

    def tree_svg(self, t: int | None = None) -> bytes | None:
        from relrl.monitor.graph import render

        t = self.rec.rows[-1]["t"] if t is None else t
        i = bisect.bisect_right(self.rec._tree_t, t) - 1
        if i < 0:
            return None
        with self._lock:
            if i not in self._svg:
                graph = self.rec.trees[i]["graph"]
                self._svg[i] = render(graph) if graph and graph.get("nodes") else None
            return self._svg[i]
