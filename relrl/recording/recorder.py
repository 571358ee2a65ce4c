"""The session's side of the recording: hand each time unit to the writer process.

:class:`Recorder` starts :mod:`relrl.recording.child` (a Python process of its own, in a
session of its own so a Ctrl-C meant for the robot does not cut the file) and writes to its
standard input what a time unit produced: the trace line the session wrote anyway and, when a
frame is recorded, its JPEG -- a few microseconds of the control loop's time. The writer
process encodes the channels, writes the MCAP file and serves Foxglove; a slower disk makes
the loop wait (the pipe is the bound) rather than lose a time unit. One clock: the session's
wall clock in nanoseconds, read once per time unit. The pipe holds :data:`PIPE_BYTES`, so a
writer that waits for a core on a busy machine does not hold the session up at once.

Example::

    rec = Recorder(foxglove="127.0.0.1:8765")   # rec.url: where Foxglove connects
    rec.open("runs/s1/session.mcap")
    rec.session({"episode": "watch", ...})
    rec.unit(time.time_ns(), trace_line, jpeg)
    rec.close_file({"relrl.session": manifest})
    rec.close()
"""

from __future__ import annotations

import json
import select
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from relrl.errors import ConfigError, OutputError
from relrl.recording.channels import to_json
from relrl.recording.child import pack

__all__ = ["Recorder"]

#: seconds the writer process may take to start or answer (imports on a loaded machine).
REPLY_SECONDS = 60.0
#: the pipe is flushed at least this often (the live view's latency).
FLUSH_SECONDS = 0.05
#: room in the pipe to the writer: about 600 time units of trace lines.
PIPE_BYTES = 1 << 20
#: what the session buffers before a write to the pipe (fewer system calls and wake-ups).
BUFFER_BYTES = 1 << 16


def _widen(pipe: Any) -> None:
    """Give the pipe :data:`PIPE_BYTES` of room where the system allows it (Linux): the
    session goes on while the writer waits for a core on a busy machine."""
    import fcntl

    try:
        fcntl.fcntl(pipe.fileno(), getattr(fcntl, "F_SETPIPE_SZ", 1031), PIPE_BYTES)
    except OSError:  # above the system's limit (/proc/sys/fs/pipe-max-size): its default
        pass


class Recorder:
    """The writer process and the pipe to it.

    Args:
        foxglove: serve the channels live at ``HOST:PORT`` (``""``: 127.0.0.1:8765), or
            ``None``.
        origins: web origins whose pages may connect to the live server (none by default).

    Attributes:
        url: where Foxglove connects (``None`` without ``foxglove``).
        token: the token required off localhost, or ``None``.

    Raises:
        ConfigError: the Foxglove address cannot be served.
        OutputError: the writer process cannot start.
    """

    def __init__(self, foxglove: str | None = None, origins: tuple[str, ...] = ()) -> None:
        cmd = [sys.executable, "-m", "relrl.recording.child"]
        if foxglove is not None:
            cmd += ["--foxglove", foxglove]
            cmd += [f"--origin={origin}" for origin in origins]
        self._err = tempfile.TemporaryFile()  # noqa: SIM115 - read when the writer fails
        self._proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                      stderr=self._err, start_new_session=True,
                                      bufsize=BUFFER_BYTES)
        self._pipe = self._proc.stdin
        _widen(self._pipe)
        self._flushed = time.monotonic()
        self._reported = False
        self.path: Path | None = None
        self.frames = 0
        self.frame_bytes = 0
        try:
            ready = self._reply()
        except BaseException:
            self._kill()
            raise
        if "error" in ready:
            self._kill()
            raise ConfigError(ready["error"])
        self.url: str | None = ready.get("url")
        self.token: str | None = ready.get("token")

    # -- the pipe ---------------------------------------------------------------------------

    def _failed(self) -> OutputError:
        self._reported = True  # raised once, where it happened
        self._err.seek(0)
        lines = [x for x in self._err.read().decode("utf-8", "replace").splitlines() if x]
        why = lines[-1] if lines else f"it exited with status {self._proc.poll()}"
        return OutputError(f"the recording's writer stopped: {why}")

    def _send(self, record: bytes, flush: bool = False) -> None:
        try:
            self._pipe.write(record)
            now = time.monotonic()
            if flush or now - self._flushed >= FLUSH_SECONDS:
                self._pipe.flush()
                self._flushed = now
        except (BrokenPipeError, ValueError, OSError):
            raise self._failed() from None

    def _reply(self) -> dict[str, Any]:
        out = self._proc.stdout
        ready, _, _ = select.select([out], [], [], REPLY_SECONDS)
        line = out.readline() if ready else b""
        if not line:
            raise self._failed()
        return json.loads(line)

    def _kill(self) -> None:
        if self._proc.poll() is None:
            self._proc.kill()
        self._proc.wait()
        self._err.close()

    # -- what a session hands over ----------------------------------------------------------

    def open(self, path: str | Path) -> None:
        """Start writing the MCAP file ``path`` (created there, never over a file).

        Raises:
            OutputError: it cannot be created.
        """
        self._send(pack(b"O", 0, str(path).encode()), flush=True)
        reply = self._reply()
        if "error" in reply:
            raise OutputError(reply["error"])
        self.path = Path(path)

    def session(self, info: dict[str, Any]) -> None:
        """What the session runs (once, at the start)."""
        self._send(pack(b"S", time.time_ns(), to_json(info)))

    def unit(self, ns: int, line: bytes, jpeg: bytes | None = None) -> None:
        """A time unit: its trace line (JSON) and, when one was recorded, its frame."""
        if jpeg:
            self.frames += 1
            self.frame_bytes += len(jpeg)
        self._send(pack(b"U", ns, line, jpeg or b""))

    def last_frame(self, ns: int, perception: dict[str, Any], jpeg: bytes) -> None:
        """A frame after the last unit (``perception``: ``t``, ``overlay``, ``frame``,
        ``frame_looking_at``)."""
        self.frames += 1
        self.frame_bytes += len(jpeg)
        self._send(pack(b"F", ns, to_json(perception), jpeg))

    def tree(self, t: int, graph: dict[str, Any] | None) -> None:
        """The learner's tree, when it changed."""
        self._send(pack(b"T", time.time_ns(), to_json({"t": t, "graph": graph})))

    def event(self, kind: str, t: int, **data: Any) -> None:
        """An evaluation or a naming execution."""
        self._send(pack(b"E", time.time_ns(), to_json({"kind": kind, "t": t, **data})))

    def attach(self, name: str, media_type: str, data: bytes) -> None:
        """A file carried inside the recording (the script, the domain)."""
        self._send(pack(b"A", 0, name.encode(), media_type.encode(), data))

    def close_file(self, metadata: dict[str, dict[str, Any]] | None = None) -> int:
        """Add ``metadata`` (name -> JSON-ready dict), close the file with its summary and
        wait until it is on disk; returns its size (0 when none is open; safe twice)."""
        if self.path is None:
            return 0
        for name, value in (metadata or {}).items():
            self._send(pack(b"M", 0, name.encode(), to_json(value)))
        self._send(pack(b"C", 0), flush=True)
        self.path = None
        return int(self._reply().get("closed", 0))

    def stats(self) -> dict[str, int]:
        """Frames handed over and their bytes."""
        return {"frames": self.frames, "frame_bytes": self.frame_bytes}

    def close(self) -> None:
        """Close the file (when open) and end the writer process (safe twice; a writer that
        already failed was reported when it did, and is only cleaned up)."""
        if self._pipe.closed:
            return
        failed: OutputError | None = None
        if self._proc.poll() is None:
            try:
                self.close_file()
            except OutputError as exc:
                failed = exc
        try:
            self._pipe.close()
        except OSError:  # the writer is gone: what was buffered has nowhere to go
            pass
        try:
            code = self._proc.wait(timeout=REPLY_SECONDS)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            code = self._proc.wait()
        if failed is None and code != 0 and not self._reported:
            failed = self._failed()
        self._err.close()
        if failed is not None:
            raise failed
