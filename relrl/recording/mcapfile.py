"""A session's MCAP file as it is written: chunked, indexed, compressed, readable after a crash.

:class:`McapFile` writes the channels of :mod:`relrl.recording.channels` with the ``mcap``
library's writer (zstd-compressed chunks with message indexes and a summary at the end, so
Foxglove and ``mcap`` tools seek in it). A chunk is closed when it reaches
:data:`CHUNK_BYTES` or :data:`CHUNK_SECONDS` after its first message, whichever comes first,
and handed to the operating system at once: a session killed outright (``kill -9``, power
kept) leaves a file that is readable up to its last closed chunk -- at most a second of the
session is lost. ``relrl replay`` reads such a file and says where it was cut.

The file is the one output of a run that is appended to while the run goes on, so it cannot
be written through a temporary file and a rename. A session makes it empty through relrl's
one writer first (:func:`relrl.outdir.open_stream`: the name journalled in the claimed
folder, whatever was there replaced, never written through); this process then opens it
with ``O_NOFOLLOW`` and writes only into an empty regular file -- or, given no such file,
creates it with ``O_CREAT | O_EXCL | O_NOFOLLOW``. Either way it is never a link and never
an earlier file written over, mode 0644 less the umask, and ``fsync``-ed when closed.
"""

from __future__ import annotations

import errno
import os
import stat
import time
from pathlib import Path
from typing import Any

from relrl.errors import OutputError
from relrl.recording.channels import CHANNELS, Channel

__all__ = ["CHUNK_BYTES", "CHUNK_SECONDS", "McapFile"]

#: a chunk is closed at this size (uncompressed) ...
CHUNK_BYTES = 1 << 20
#: ... or this many seconds after it was started, whichever comes first.
CHUNK_SECONDS = 1.0


def _open_new(path: Path) -> Any:
    """Open ``path`` for writing: an empty regular file made for it, or created here; never
    a link, never a file with something in it."""
    nofollow = getattr(os, "O_NOFOLLOW", 0)
    mask = os.umask(0o022)
    os.umask(mask)
    try:
        try:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | nofollow, 0o666 & ~mask)
        except FileExistsError:
            fd = os.open(path, os.O_WRONLY | nofollow)
            st = os.fstat(fd)
            if not stat.S_ISREG(st.st_mode) or st.st_size:
                os.close(fd)
                raise OutputError(f"cannot write {path}: a file is already there") from None
    except OutputError:
        raise
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise OutputError(f"cannot write {path}: a link is there (relrl never writes "
                              "through a link)") from None
        raise OutputError(f"cannot write {path}: {exc.strerror or exc}") from None
    return os.fdopen(fd, "wb", buffering=1 << 16)


class McapFile:
    """An MCAP file being written, with every channel of a session registered.

    Args:
        path: the file to create (refused when something is there).
        library: the writer's name, stored in the file's header.

    Raises:
        OutputError: the file cannot be created.
    """

    def __init__(self, path: str | Path, library: str = "relrl") -> None:
        from mcap.writer import CompressionType, Writer

        self.path = Path(path)
        self._fh = _open_new(self.path)
        self._writer = Writer(self._fh, chunk_size=CHUNK_BYTES, compression=CompressionType.ZSTD)
        self._writer.start(profile="", library=library)
        self._ids: dict[str, int] = {}
        self._seq: dict[str, int] = {}
        for ch in CHANNELS:
            schema = self._writer.register_schema(ch.schema, ch.schema_encoding, ch.schema_data)
            self._ids[ch.topic] = self._writer.register_channel(ch.topic, ch.encoding, schema)
            self._seq[ch.topic] = 0
        self.messages = 0
        self._chunk_due: float | None = None
        self._closed = False

    def write(self, channel: Channel, log_time: int, data: bytes) -> None:
        """Add one message (``log_time`` in nanoseconds since the epoch)."""
        seq = self._seq[channel.topic] = self._seq[channel.topic] + 1
        self._writer.add_message(self._ids[channel.topic], log_time, data, log_time, seq)
        self.messages += 1
        now = time.monotonic()
        if self._chunk_due is None:
            self._chunk_due = now + CHUNK_SECONDS
        elif now >= self._chunk_due:
            self.flush()

    def flush(self) -> None:
        """Close the chunk in progress and hand everything to the operating system."""
        self._writer.flush()
        self._chunk_due = None

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        """A metadata record (string keys and values)."""
        self._writer.add_metadata(name, data)

    def add_attachment(self, name: str, media_type: str, data: bytes) -> None:
        """A file carried inside the recording (the episode script, the domain)."""
        now = time.time_ns()
        self._writer.add_attachment(now, now, name, media_type, data)

    def close(self) -> int:
        """Write the summary and the footer, ``fsync`` and close (safe twice).

        Returns:
            the file's size in bytes.
        """
        if not self._closed:
            self._closed = True
            try:
                self._writer.finish()
                self._fh.flush()
                os.fsync(self._fh.fileno())
            except OSError as exc:
                raise OutputError(f"cannot write {self.path}: {exc.strerror or exc}") \
                    from None
            finally:
                self._fh.close()
        return self.path.stat().st_size
