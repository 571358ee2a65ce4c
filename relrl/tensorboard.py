"""Scalars as TensorBoard event files, written without TensorFlow or any other package.

``tensorboard --logdir runs/`` reads what relrl writes: ``relrl run --out DIR`` writes
``DIR/events.out.tfevents.relrl`` as the session goes (reward, every necessity unit's
output, running CGI, eye contacts, working memory per time unit; each evaluation's CGI; each
naming execution's outcomes), and ``relrl experiment`` writes ``DIR/tensorboard/RUN/`` per
learner and per job (the CGI curves, memory, eye contacts) with its results. tbparse, and
TensorBoard's own ``EventAccumulator``, read the same files into pandas.

The format (TensorFlow's ``TFRecord`` of ``Event`` protocol buffers, what TensorBoard reads):
each record is its length (8 bytes, little-endian), the masked CRC-32C of the length, the
data, and the masked CRC-32C of the data. The first event says the file's version
(``brain.Event:2``); each later one holds a step, its wall time and a summary with one value
per tag (``tag``, ``simple_value``). One event carries every scalar of a step, so a time
unit costs one record, not one per scalar, and the checksum is compiled
(:mod:`relrl._crc_kernel`).
"""

from __future__ import annotations

import logging
import math
import struct
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

__all__ = ["EVENT_FILE", "ScalarLog", "crc32c", "event_file", "write_event_file"]

log = logging.getLogger(__name__)

#: the event file's name in its folder (TensorBoard reads files whose name holds "tfevents").
EVENT_FILE = "events.out.tfevents.relrl"
#: seconds between writes of a growing log's buffered events.
FLUSH_SECONDS = 1.0


_KERNEL: Any = None


def crc32c(data: bytes) -> int:
    """CRC-32C (Castagnoli) of ``data``, the checksum of TensorFlow's records."""
    global _KERNEL
    if _KERNEL is None:  # numba is loaded on first use
        import numpy as np

        from relrl._crc_kernel import TABLE, crc32c

        _KERNEL = lambda raw: crc32c(np.frombuffer(raw, dtype=np.uint8), TABLE)  # noqa: E731
    return int(_KERNEL(data))


def _masked(data: bytes) -> bytes:
    c = crc32c(data)
    return struct.pack("<I", (((c >> 15) | (c << 17)) + 0xA282EAD8) & 0xFFFFFFFF)


def _varint(n: int) -> bytes:
    out = bytearray()
    n &= (1 << 64) - 1  # int64 as protobuf writes it
    while True:
        byte = n & 0x7F
        n >>= 7
        if n:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def _field(number: int, payload: bytes) -> bytes:
    """A length-delimited field (wire type 2)."""
    return _varint(number << 3 | 2) + _varint(len(payload)) + payload


_VALUE_HEADS: dict[str, bytes] = {}  # tag -> a Value's bytes up to its float


def _value_head(tag: str) -> bytes:
    head = _VALUE_HEADS.get(tag)
    if head is None:
        inner = _field(1, tag.encode()) + b"\x15"
        head = _VALUE_HEADS[tag] = _varint(1 << 3 | 2) + _varint(len(inner) + 4) + inner
    return head


def _event(wall_time: float, step: int, scalars: Mapping[str, float] | None = None,
           version: str | None = None) -> bytes:
    """One ``Event``: wall_time (1, double), step (2, int64), file_version (3) or a summary
    (5) of ``Value``s: tag (1), simple_value (2, float)."""
    out = b"\x09" + struct.pack("<d", wall_time) + b"\x10" + _varint(int(step))
    if version is not None:
        out += _field(3, version.encode())
    if scalars:
        pack = struct.Struct("<f").pack
        out += _field(5, b"".join(_value_head(tag) + pack(value)
                                  for tag, value in scalars.items()))
    return out


def _record(data: bytes) -> bytes:
    length = struct.pack("<Q", len(data))
    return length + _masked(length) + data + _masked(data)


def _finite(scalars: Mapping[str, Any]) -> dict[str, float]:
    """The values that are numbers (not None, NaN or infinite), as floats."""
    out = {}
    for tag, value in scalars.items():
        if isinstance(value, bool) or not isinstance(value, int | float):
            continue
        if math.isfinite(value):
            out[tag] = float(value)
    return out


def event_file(points: Iterable[tuple[int, Mapping[str, Any]]],
               wall_time: float | None = None) -> bytes:
    """A whole event file: its version, then one event per ``(step, {tag: value})``
    (values that are not finite numbers are left out; a step without any, too)."""
    now = time.time() if wall_time is None else wall_time
    out = [_record(_event(now, 0, version="brain.Event:2"))]
    for step, scalars in points:
        values = _finite(scalars)
        if values:
            out.append(_record(_event(now, step, values)))
    return b"".join(out)


def write_event_file(folder: str | Path,
                     points: Iterable[tuple[int, Mapping[str, Any]]]) -> Path:
    """Write :data:`EVENT_FILE` in ``folder`` (made when missing) whole, atomically, through
    :mod:`relrl.outdir` (a table: it does not take the space held back for the results)."""
    from relrl.outdir import write_atomic

    return write_atomic(Path(folder) / EVENT_FILE, event_file(points), spare=False)


class ScalarLog:
    """An event file that grows as a run goes: :meth:`add` a step's scalars; they reach
    the file at most :data:`FLUSH_SECONDS` apart (TensorBoard shows them while the run goes)
    and at :meth:`close` (safe twice). The file is a view of numbers the run keeps elsewhere
    (the trace): when it cannot be written (a full disk) the run goes on without it (run.log
    says so), the file ending at its last whole record.

    Args:
        path: the file (a new one, through :func:`relrl.outdir.open_stream`: whatever was
            there is replaced, never written through).
    """

    def __init__(self, path: str | Path) -> None:
        from relrl.outdir import open_stream

        self.path = Path(path)
        self._file = open_stream(self.path, binary=True)
        self._pending = [_record(_event(time.time(), 0, version="brain.Event:2"))]
        self._next = 0.0

    def add(self, step: int, scalars: Mapping[str, Any]) -> None:
        """The scalars of one step (values that are not finite numbers are left out)."""
        if self._file.closed:
            return
        values = _finite(scalars)
        if values:
            self._pending.append(_record(_event(time.time(), step, values)))
        now = time.perf_counter()
        if now >= self._next:
            self._next = now + FLUSH_SECONDS
            self.flush()

    def flush(self) -> None:
        """Write what is buffered."""
        from relrl.errors import OutputError

        if self._pending and not self._file.closed:
            try:
                self._file.write(b"".join(self._pending))  # whole records, or none of them
            except OutputError as exc:
                # said in run.log; the trace's own write meets the same cause and says it
                log.debug("TensorBoard's event file is not written any more (the trace keeps "
                          "every number): %s", exc)
                self._file.close()
            self._pending = []

    def close(self) -> None:
        """Write what is buffered and close the file (safe twice)."""
        if not self._file.closed:
            self.flush()
            self._file.close()
