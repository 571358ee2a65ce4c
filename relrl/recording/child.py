"""The recording's writer process: ``python -m relrl.recording.child [--foxglove ADDRESS
[--origin ORIGIN ...]]``.

The session (:class:`~relrl.recording.recorder.Recorder`) hands over, through this process's
standard input, what each time unit produced -- the trace line it wrote anyway and the frame's
JPEG -- as framed records (:func:`pack`); this process encodes the channels
(:class:`~relrl.recording.encoder.Encoder`) and writes them to the MCAP file
(:class:`~relrl.recording.mcapfile.McapFile`) and/or serves them live
(:class:`~relrl.monitor.foxglove.FoxgloveServer`). So the encoding and writing run on a core
of their own, not in the control loop's process and its interpreter lock.

Replies (one JSON line each on standard output) answer the records that need one: ready
(with the Foxglove address), a file opened or closed. An error writing the file is one line
on standard error and exit status 2. End of input -- the session closed the pipe, or was
killed -- closes the file with its summary and stops the server: a session killed with
``kill -9`` still leaves a complete file up to the last unit it handed over.
"""

from __future__ import annotations

import argparse
import json
import struct
import sys
from typing import IO, Any

__all__ = ["pack", "read_record"]

_HEAD = struct.Struct("<cQB")
_LEN = struct.Struct("<I")


def pack(kind: bytes, ns: int, *parts: bytes) -> bytes:
    """One record: a kind byte, a log time, and its parts (each length-prefixed)."""
    out = [_HEAD.pack(kind, ns, len(parts))]
    for part in parts:
        out += [_LEN.pack(len(part)), part]
    return b"".join(out)


def _exactly(stream: IO[bytes], n: int) -> bytes | None:
    data = stream.read(n)
    return data if data is not None and len(data) == n else None


def read_record(stream: IO[bytes]) -> tuple[bytes, int, list[bytes]] | None:
    """The next record, or ``None`` at the end (or a record cut by the end)."""
    head = _exactly(stream, _HEAD.size)
    if head is None:
        return None
    kind, ns, n = _HEAD.unpack(head)
    parts = []
    for _ in range(n):
        size = _exactly(stream, _LEN.size)
        if size is None:
            return None
        length = _LEN.unpack(size)[0]
        part = _exactly(stream, length) if length else b""
        if part is None:
            return None
        parts.append(part)
    return kind, ns, parts


def _reply(**data: Any) -> None:
    sys.stdout.write(json.dumps(data) + "\n")
    sys.stdout.flush()


def main(argv: list[str] | None = None) -> int:
    """Serve records from standard input until its end."""
    from relrl.errors import UserError
    from relrl.recording.encoder import Encoder
    from relrl.recording.mcapfile import McapFile

    parser = argparse.ArgumentParser(prog="relrl.recording.child")
    parser.add_argument("--foxglove", default=None, metavar="HOST:PORT")
    parser.add_argument("--origin", action="append", default=[], metavar="ORIGIN")
    args = parser.parse_args(argv)
    server = None
    if args.foxglove is not None:
        from relrl.monitor.foxglove import FoxgloveServer

        try:
            server = FoxgloveServer(args.foxglove or None,
                                    origins=tuple(args.origin)).start()
        except UserError as exc:
            _reply(error=str(exc))
            return 2
    _reply(ready=True, url=server.url if server else None,
           token=server.token if server else None)
    encoder = Encoder()
    mcap: McapFile | None = None
    stdin = sys.stdin.buffer
    try:
        while (record := read_record(stdin)) is not None:
            kind, ns, parts = record
            messages: list[Any] = []
            if kind == b"U":
                messages = encoder.unit(ns, json.loads(parts[0]), parts[1] or None)
            elif kind == b"F":
                messages = encoder.last_frame(ns, json.loads(parts[0]), parts[1])
            elif kind == b"S":
                messages = encoder.session(ns, json.loads(parts[0]))
            elif kind == b"T":
                messages = encoder.tree(ns, json.loads(parts[0]))
            elif kind == b"E":
                messages = encoder.event(ns, json.loads(parts[0]))
            elif kind == b"O":
                try:
                    mcap = McapFile(parts[0].decode(), library="relrl")
                    _reply(opened=str(mcap.path))
                except UserError as exc:
                    _reply(error=str(exc))
            elif kind == b"A" and mcap is not None:
                mcap.add_attachment(parts[0].decode(), parts[1].decode(), parts[2])
            elif kind == b"M" and mcap is not None:
                mcap.add_metadata(parts[0].decode(), {"json": parts[1].decode()})
            elif kind == b"C":
                size = mcap.close() if mcap is not None else 0
                mcap = None
                _reply(closed=size)
            for message in messages:
                if mcap is not None:
                    mcap.write(*message)
                if server is not None:
                    server.write(*message)
    except (UserError, OSError) as exc:  # the disk is full, the folder went away
        print(f"relrl: the recording stopped: {exc}", file=sys.stderr, flush=True)
        return 2
    finally:
        try:
            if mcap is not None:  # the end of input, or an error: the file gets its summary
                mcap.close()
        except (UserError, OSError):
            pass
        if server is not None:
            server.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
