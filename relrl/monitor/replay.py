"""A recorded session read back for ``relrl replay DIR`` (see :mod:`relrl.episodes.recording`).

:class:`Recording` reads the folder (trace, frame index, trees, events, session, summary) and
never writes to it; :class:`ReplaySource` answers the monitor's page for any time unit.

A recording is untrusted data. Replay reads only regular files inside the folder, never
through a symbolic link (``frames/000001.jpg -> /etc/passwd`` is not served; a linked
``frames/`` or ``trace.jsonl`` is refused), and checks every line before serving
(:mod:`relrl.monitor.schema`): text that is not UTF-8, a line that is not a JSON object, a
time unit that is not a whole number from 0 to 2**53, JSON nested too deeply, a value of the
wrong type, a time unit twice -- each is one line naming the file and the line. Lines need
not be in order (they are sorted by time unit); a last line cut short by a session that was
stopped is left out.
"""

from __future__ import annotations

import bisect
import errno
import json
import logging
import os
import re
import stat
import threading
from pathlib import Path
from typing import Any

from relrl.errors import UserError
from relrl.monitor import schema

__all__ = ["Recording", "ReplaySource"]

log = logging.getLogger(__name__)

#: the largest frame file served, in bytes (a recorded frame is tens of kilobytes).
MAX_FRAME_BYTES = 32 << 20
#: time units are whole numbers from 0 to this (what a browser's numbers hold exactly).
MAX_T = 2 ** 53
_FILE_FLAGS = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC
_DIR_FLAGS = os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC


class _NotInside(OSError):
    """A file of the recording that is a link, or not a regular file."""


def _open_inside(folder: Path, *parts: str) -> int | None:
    """A descriptor of the regular file ``folder/parts...``, reached without following a
    link below ``folder``; ``None`` when there is no such file.

    Raises:
        _NotInside: a part is a symbolic link, or the file is not a regular file.
    """
    fds = [os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)]
    try:
        for i, part in enumerate(parts):
            last = i == len(parts) - 1
            try:
                fd = os.open(part, _FILE_FLAGS if last else _DIR_FLAGS, dir_fd=fds[-1])
            except FileNotFoundError:
                return None
            except OSError as exc:
                if exc.errno in (errno.ELOOP, errno.ENOTDIR, errno.EMLINK):
                    if stat.S_ISLNK(os.stat(part, dir_fd=fds[-1],
                                            follow_symlinks=False).st_mode):
                        raise _NotInside("a symbolic link") from None
                    raise _NotInside("not a folder") from None
                raise
            fds.append(fd)
        mode = os.fstat(fds[-1]).st_mode
        if not stat.S_ISREG(mode):
            raise _NotInside("a folder" if stat.S_ISDIR(mode) else "not a regular file")
        return fds.pop()
    finally:
        for fd in fds:
            os.close(fd)


def _read(folder: Path, *parts: str, limit: int | None = None) -> bytes | None:
    """The bytes of ``folder/parts...`` (see :func:`_open_inside`); ``None`` when absent.

    Raises:
        _NotInside: a link, or not a regular file; OSError: it cannot be read, or is
            larger than ``limit`` (EFBIG).
    """
    fd = _open_inside(folder, *parts)
    if fd is None:
        return None
    with os.fdopen(fd, "rb") as fh:
        if limit is not None and os.fstat(fh.fileno()).st_size > limit:
            raise OSError(errno.EFBIG, f"larger than {limit} bytes")
        return fh.read()


def _read_file(path: Path) -> bytes | None:
    """A top-level file of the recording, or ``None``; a link or an unreadable file is one
    line (UserError)."""
    try:
        return _read(path.parent, path.name)
    except _NotInside as exc:
        raise UserError(f"{path}: {exc}; replay reads only regular files inside the "
                        "recording, never through a link") from None
    except OSError as exc:
        raise UserError(f"{path}: cannot be read ({exc.strerror or exc})") from None


def _why(exc: BaseException) -> str:
    if isinstance(exc, RecursionError):
        return "nested too deeply"
    if isinstance(exc, json.JSONDecodeError):
        return f"{exc.msg} at column {exc.colno}"
    return str(exc).split(";")[0][:120]


def _not_utf8(path: Path, data: bytes, exc: UnicodeDecodeError, line: int = 0) -> UserError:
    """``path:LINE: not UTF-8 text (byte 0xNN at column C)``; ``data`` is the file, or
    line ``line`` of it."""
    at = exc.start
    start = data.rfind(b"\n", 0, at) + 1
    line = line or data.count(b"\n", 0, at) + 1
    return UserError(f"{path}:{line}: not UTF-8 text (byte 0x{data[at]:02x} at column "
                     f"{at - start + 1})")


def _jsonl(path: Path, shape: dict[str, Any]) -> list[tuple[int, dict[str, Any]]]:
    """The lines of a JSON-lines file as ``(line number, checked object)``."""
    data = _read_file(path)
    if data is None:
        return []
    lines = data.split(b"\n")
    cut = lines.pop() != b""  # the last line has no line end: a stopped session's
    if cut:
        lines.append(data[data.rfind(b"\n") + 1:])
    rows = []
    for n, raw in enumerate(lines, 1):
        if not raw.strip():
            continue
        try:
            value = schema.loads(raw.decode("utf-8"))
        except (ValueError, RecursionError) as exc:
            if cut and n == len(lines) and n > 1:
                break  # only a cut last line is forgiven
            if isinstance(exc, UnicodeDecodeError):
                raise _not_utf8(path, raw, exc, n) from None
            raise UserError(f"{path}:{n}: not a JSON line ({_why(exc)})") from None
        try:
            row = schema.check(value, shape, null=False)
        except (schema.ShapeError, RecursionError) as exc:
            raise UserError(f"{path}:{n}: {_why(exc)}") from None
        for key in ("t", "index"):
            if key in row and (key in shape or f"{key}!" in shape):
                low = 1 if key == "index" else 0
                if not low <= row[key] <= MAX_T:
                    raise UserError(f"{path}:{n}: {key} must be a whole number from {low} "
                                    f"to 2**53, not {row[key]}")
        rows.append((n, row))
    return rows


def _json(path: Path, shape: dict[str, Any]) -> dict[str, Any]:
    """A JSON object file checked against ``shape`` (``{}`` when absent)."""
    data = _read_file(path)
    if data is None:
        return {}
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise _not_utf8(path, data, exc) from None
    try:
        value = schema.loads(text)
    except json.JSONDecodeError as exc:
        raise UserError(f"{path}:{exc.lineno}: not JSON ({exc.msg})") from None
    except (ValueError, RecursionError) as exc:
        raise UserError(f"{path}:1: not JSON ({_why(exc)})") from None
    if not isinstance(value, dict):
        raise UserError(f"{path}:1: not a JSON object (the file holds a "
                        f"{type(value).__name__})")
    try:
        return schema.check(value, shape)
    except (schema.ShapeError, RecursionError) as exc:
        field = str(exc).split(" ", 1)[0].split(".")[0].split("[")[0]
        found = re.search(rf'"{re.escape(field)}"\s*:', text)
        line = text.count("\n", 0, found.start()) + 1 if found else 1
        raise UserError(f"{path}:{line}: {_why(exc)}") from None


def _sorted(path: Path, rows: list[tuple[int, dict[str, Any]]], *, unique: bool
            ) -> list[dict[str, Any]]:
    """The rows in time order (stable); ``unique``: a time unit twice is an error."""
    rows = sorted(rows, key=lambda r: r[1]["t"])
    if unique:
        for (n0, a), (n1, b) in zip(rows, rows[1:], strict=False):
            if a["t"] == b["t"]:
                first, again = sorted((n0, n1))
                raise UserError(f"{path}:{again}: time unit {a['t']} again (it is on line "
                                f"{first} too)")
    return [row for _, row in rows]


class Recording:
    """A session folder: ``trace.jsonl`` and, when recorded, frames, trees and events.

    Raises:
        UserError: no such folder, no trace in it, or a file that is not what replay reads
            (one line naming the file and the line).
    """

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise UserError(f"{folder}: no such folder")
        trace = self.folder / "trace.jsonl"
        if not trace.exists() and not trace.is_symlink():
            raise UserError(f"{folder}: not a recorded session (no trace.jsonl); record one "
                            "with relrl run EPISODE --out DIR --record")
        frames = self.folder / "frames"
        if frames.is_symlink():
            raise UserError(f"{frames}: a symbolic link; replay reads only what is inside "
                            "the recording (copy the frames into it)")
        self.rows = _sorted(trace, _jsonl(trace, schema.TRACE_ROW), unique=True)
        if not self.rows:
            raise UserError(f"{trace}: the trace is empty")
        self.frames = _sorted(self.folder / "frames.jsonl",
                              _jsonl(self.folder / "frames.jsonl", schema.FRAME), unique=False)
        self.trees = _sorted(self.folder / "trees.jsonl",
                             _jsonl(self.folder / "trees.jsonl", schema.TREE_ROW), unique=False)
        self.events = [e for _, e in _jsonl(self.folder / "events.jsonl", schema.EVENT)]
        self.manifest = _json(self.folder / "session.json", schema.MANIFEST)
        self.summary = _json(self.folder / "summary.json", schema.SUMMARY)
        self._t = [r["t"] for r in self.rows]
        self._frame_t = [f["t"] for f in self.frames]
        self._frame_index = {f["index"] for f in self.frames}
        self._tree_t = [x["t"] for x in self.trees]
        self._warned: set[str] = set()

    @property
    def necessities(self) -> list[str]:
        """The necessity units, in order."""
        return self.manifest.get("necessities") or list(self.rows[0].get("activation") or {})

    def row(self, t: int) -> dict[str, Any] | None:
        """The trace line of time unit ``t`` (``None`` outside the session)."""
        i = bisect.bisect_left(self._t, t)
        return self.rows[i] if i < len(self._t) and self._t[i] == t else None

    def frame_at(self, t: int) -> dict[str, Any] | None:
        """The newest recorded frame at or before time unit ``t``."""
        i = bisect.bisect_right(self._frame_t, t) - 1
        return self.frames[i] if i >= 0 else None

    def frame_bytes(self, index: int) -> bytes | None:
        """The JPEG bytes of recorded frame ``index`` (from 1); ``None`` when there is none
        -- or when the file is a link, not a regular file, or too large (logged)."""
        if index not in self._frame_index:
            return None
        name = f"{index:06d}.jpg"
        try:
            return _read(self.folder, "frames", name, limit=MAX_FRAME_BYTES)
        except OSError as exc:
            if name not in self._warned:  # once a frame, however often it is asked for
                self._warned.add(name)
                log.warning("replay: frames/%s is not served: %s", name,
                            exc if isinstance(exc, _NotInside) else exc.strerror or exc)
            return None

    def tree_index(self, t: int) -> int:
        """The index in :attr:`trees` of the tree as it was at time unit ``t`` (-1: none)."""
        return bisect.bisect_right(self._tree_t, t) - 1

    def tree_at(self, t: int) -> dict[str, Any] | None:
        """The learner's tree as it was at time unit ``t``."""
        i = self.tree_index(t)
        return self.trees[i]["graph"] if i >= 0 else None


class ReplaySource:
    """What the monitor's page shows of a :class:`Recording`."""

    mode = "replay"
    period = 0.5

    def __init__(self, recording: Recording) -> None:
        self.rec = recording
        self._svg: dict[int, Any] = {}
        self._lock = threading.Lock()

    def info(self) -> dict[str, Any]:
        rec, m, s = self.rec, self.rec.manifest, self.rec.summary
        return {"episode": m.get("episode", s.get("episode", rec.folder.name)),
                "learner": (m.get("learner") or {}).get("name",
                                                       (s.get("learner") or {}).get("name")),
                "seed": m.get("seed"), "steps": len(rec.rows),
                "first": rec.rows[0]["t"], "last": rec.rows[-1]["t"],
                "necessities": rec.necessities, "responses": m.get("responses"),
                "perception": m.get("perception"), "where": m.get("where") or s.get("where"),
                "frames": len(rec.frames), "events": rec.events, "folder": str(rec.folder),
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
        out["tree_version"] = self.rec.tree_index(t)
        return out

    def series(self) -> list[list[Any]]:
        names = self.rec.necessities
        return [[r["t"], [(r.get("activation") or {}).get(n, 0.0) for n in names],
                 r.get("reward", 0.0)] for r in self.rec.rows]

    def frame_jpeg(self, index: int) -> bytes | None:
        return self.rec.frame_bytes(index)

    def tree_picture(self, t: int | None = None) -> Any:
        """The tree as it was at time unit ``t`` (default: the end), drawn
        (a :class:`~relrl.monitor.graph.Picture`), or ``None``.

        Raises:
            GraphError: the tree cannot be drawn.
        """
        from relrl.monitor.server import drawn

        i = self.rec.tree_index(self.rec.rows[-1]["t"] if t is None else t)
        if i < 0:
            return None
        with self._lock:
            if i not in self._svg:
                self._svg[i] = drawn(self.rec.trees[i]["graph"])
            svg = self._svg[i]
        if isinstance(svg, Exception):
            raise svg
        return svg
