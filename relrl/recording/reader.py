"""A recorded session read back from its MCAP file (``relrl replay FILE.mcap``).

:class:`McapRecording` reads the file once, in file order, with the ``mcap`` library's stream
reader (chunk CRCs checked), joins each time unit's channels back into its trace row, and
keeps the trees, the events and where each frame is. It answers what the replay page asks
(:meth:`row`, :meth:`frame_at`, :meth:`frame_bytes`, :meth:`tree_at`) as a recorded folder
does, and never writes.

A file cut short (the session killed before it closed the file) is read up to its last
complete chunk, and :attr:`McapRecording.cut` says so; anything else wrong -- not an MCAP
file, a damaged chunk, a message that is not what its channel says, no session in it -- is a
:class:`~relrl.errors.UserError` naming the file: one line, exit status 2.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

from relrl.errors import UserError
from relrl.monitor import schema
from relrl.monitor.replay import MAX_T, Recording
from relrl.recording.channels import EVENTS, IMAGE, ROW_CHANNELS, SESSION, TREE, join_row

__all__ = ["MCAP_MAGIC", "McapRecording", "open_recording"]

#: the eight bytes an MCAP file starts (and, when complete, ends) with.
MCAP_MAGIC = b"\x89MCAP0\r\n"
_ROW_TOPICS = {ch.topic for ch in ROW_CHANNELS}
_FIRST = ROW_CHANNELS[0].topic  # a time unit exists when it has percepts


def _json(path: Path, topic: str, data: bytes) -> dict[str, Any]:
    try:
        msg = schema.loads(data)
    except (ValueError, RecursionError) as exc:  # UnicodeDecodeError, JSONDecodeError
        why = "nested too deeply" if isinstance(exc, RecursionError) else exc
        raise UserError(f"{path}: a message on {topic} is not JSON ({why})") from None
    if not isinstance(msg, dict):
        raise UserError(f"{path}: a message on {topic} is not a JSON object")
    if topic != SESSION.topic:
        t = msg.get("t")
        if not (isinstance(t, int) and not isinstance(t, bool) and 0 <= t <= MAX_T):
            raise UserError(f"{path}: a message on {topic} has no time unit t (a whole "
                            f"number from 0 to 2**53), found {t!r}")
    return msg


def _checked(path: Path, what: str, value: Any, shape: Any, **kw: Any) -> Any:
    """``value`` checked against the replay's shape for it (:mod:`relrl.monitor.schema`):
    the same rules as for a recorded folder's files."""
    try:
        return schema.check(value, shape, **kw)
    except (schema.ShapeError, RecursionError) as exc:
        why = "nested too deeply" if isinstance(exc, RecursionError) else str(exc)
        raise UserError(f"{path}: {what}: {why}") from None


class McapRecording(Recording):
    """A session recorded as MCAP, read whole (but the frames) when opened; answers what the
    replay page asks as a recorded folder (:class:`~relrl.monitor.replay.Recording`) does.

    Args:
        path: the ``.mcap`` file.

    Attributes:
        rows: one trace row per time unit, in order.
        frames: ``{"index", "t", "log_time"}`` per recorded frame.
        trees: ``{"t", "graph"}`` whenever the tree changed.
        events: evaluations and naming executions.
        manifest: what was run (``session.json``'s content, when the session finished).
        cut: ``None``, or why the file ends early (read up to its last complete chunk).

    Raises:
        UserError: no such file, not an MCAP file, damaged, or no session in it.
    """

    def __init__(self, path: str | Path) -> None:  # the file is read here, not the folder
        self.path = Path(path)
        self.folder = self.path.parent
        if not self.path.is_file():
            raise UserError(f"{path}: no such file")
        with open(self.path, "rb") as fh:
            if fh.read(8) != MCAP_MAGIC:
                raise UserError(f"{path}: not an MCAP file")
        self.rows: list[dict[str, Any]] = []
        self.frames: list[dict[str, Any]] = []
        self.trees: list[dict[str, Any]] = []
        self.events: list[dict[str, Any]] = []
        self.info: dict[str, Any] = {}
        self.manifest: dict[str, Any] = {}
        self.summary: dict[str, Any] = {}
        self.attachments: dict[str, bytes] = {}
        self.cut: str | None = None
        self._jpeg: dict[int, bytes] = {}  # frames of a cut file (no index to seek with)
        self._read()
        if not self.rows:
            what = "cut short before its first complete chunk" if self.cut else \
                "not a recorded relrl session (no /relrl/percepts messages)"
            raise UserError(f"{path}: {what}")
        self._t = [int(r["t"]) for r in self.rows]
        self._frame_t = [int(f["t"]) for f in self.frames]
        self._tree_t = [int(x["t"]) for x in self.trees]

    def _read(self) -> None:
        from mcap.exceptions import EndOfFile
        from mcap.records import Attachment, Channel, Footer, Message, Metadata
        from mcap.stream_reader import StreamReader

        channels: dict[int, str] = {}
        units: dict[int, list[dict[str, Any]]] = {}
        unit_at: dict[int, int] = {}  # log time -> time unit, for pairing frames
        complete = False
        with open(self.path, "rb") as fh:
            records = StreamReader(fh, validate_crcs=True, record_size_limit=1 << 30).records
            while True:
                try:
                    record = next(records)
                except StopIteration:
                    break
                except (EndOfFile, struct.error):  # cut inside a record or its length
                    break
                except Exception as exc:  # noqa: BLE001 - only the file's bytes are read
                    # here: a CRC, decompression (zstd, lz4) or record error is damage
                    raise UserError(f"{self.path}: damaged MCAP file "
                                    f"({type(exc).__name__}: {exc})") from None
                if isinstance(record, Channel):
                    channels[record.id] = record.topic
                elif isinstance(record, Message):
                    topic = channels.get(record.channel_id)
                    if topic is None:
                        raise UserError(f"{self.path}: a message on channel "
                                        f"{record.channel_id}, which was never declared")
                    self._message(topic, record, units, unit_at)
                elif isinstance(record, Metadata):
                    self._metadata(record.name, record.metadata)
                elif isinstance(record, Attachment):
                    self.attachments[record.name] = record.data
                elif isinstance(record, Footer):
                    complete = True
        if complete and self._index_agrees():  # frames are read when shown, through the
            self._jpeg.clear()                 # file's chunk index
        else:
            last = ROW_CHANNELS[-1].topic  # a unit cut in the middle of its channels
            units = {t: p for t, p in units.items() if p and last in {m["_topic"] for m in p}}
            self.cut = (f"cut short (the session was stopped before it closed the file): "
                        f"read up to its last complete chunk, {len(units)} time units")
        for parts in units.values():
            for msg in parts:
                del msg["_topic"]
        self.rows = [_checked(self.path, f"time unit {t}", join_row(parts), schema.TRACE_ROW,
                              null=False) for t, parts in sorted(units.items())]
        self.trees = sorted((_checked(self.path, f"the tree at time unit {x['t']}", x,
                                      schema.TREE_ROW, null=False) for x in self.trees),
                            key=lambda x: x["t"])
        self.events = [_checked(self.path, "an event", e, schema.EVENT, null=False)
                       for e in self.events]
        self.manifest = _checked(self.path, "metadata relrl.session", self.manifest,
                                 schema.MANIFEST)
        self.summary = _checked(self.path, "metadata relrl.summary", self.summary,
                                schema.SUMMARY)

    def _index_agrees(self) -> bool:
        """Whether the file's summary counts the frames this reading found (else its index
        is not trusted, and the frames read are kept)."""
        from mcap.reader import make_reader

        try:
            with open(self.path, "rb") as fh:
                summary = make_reader(fh).get_summary()
            ids = [i for i, ch in summary.channels.items() if ch.topic == IMAGE.topic]
            counted = sum(summary.statistics.channel_message_counts.get(i, 0) for i in ids)
        except Exception:  # noqa: BLE001 - a damaged summary: the index is not used
            return False
        return counted == len(self.frames)

    @property
    def _schema(self) -> Any:
        from mcap.records import Schema

        return Schema(id=1, name=IMAGE.schema, encoding=IMAGE.schema_encoding,
                      data=IMAGE.schema_data)

    def _message(self, topic: str, record: Any, units: dict[int, list[dict[str, Any]]],
                 unit_at: dict[int, int]) -> None:
        if topic in _ROW_TOPICS:
            msg = _json(self.path, topic, record.data)
            t = msg["t"]
            if topic == _FIRST:
                units.setdefault(t, [])
                unit_at[record.log_time] = t
            parts = units.get(t)
            if parts is not None:
                msg["_topic"] = topic
                parts.append(msg)
            elif topic == "/relrl/perception":  # the last frame, after the last unit
                unit_at[record.log_time] = t
        elif topic == IMAGE.topic:
            index = len(self.frames) + 1
            t = unit_at.get(record.log_time, max(unit_at.values(), default=0))
            self.frames.append({"index": index, "t": t, "log_time": record.log_time})
            self._jpeg[index] = record.data  # dropped when the file is complete (below)
        elif topic == TREE.topic:
            msg = _json(self.path, topic, record.data)
            self.trees.append({"t": msg["t"], "graph": msg.get("graph")})
        elif topic == EVENTS.topic:
            self.events.append(_json(self.path, topic, record.data))
        elif topic == SESSION.topic:
            self.info = _json(self.path, topic, record.data)

    def _metadata(self, name: str, data: dict[str, str]) -> None:
        if name in ("relrl.session", "relrl.summary"):
            try:
                value = schema.loads(data.get("json", "{}"))
            except (ValueError, RecursionError) as exc:
                why = "nested too deeply" if isinstance(exc, RecursionError) else exc
                raise UserError(f"{self.path}: metadata {name} is not JSON ({why})") from None
            if not isinstance(value, dict):
                raise UserError(f"{self.path}: metadata {name} is not a JSON object")
            if name == "relrl.session":
                self.manifest = value
            else:
                self.summary = value

    @property
    def necessities(self) -> list[str]:
        """The necessity units, in order."""
        return (self.manifest.get("necessities") or self.info.get("necessities")
                or list(self.rows[0].get("activation", {})))

    def frame_bytes(self, index: int) -> bytes | None:
        """The JPEG bytes of recorded frame ``index`` (from 1)."""
        if not 1 <= index <= len(self.frames):
            return None
        from mcap.reader import make_reader
        from mcap_ros2.decoder import DecoderFactory

        data = self._jpeg.get(index)
        try:
            if data is None:
                ns = self.frames[index - 1]["log_time"]
                with open(self.path, "rb") as fh:
                    for _, _, _, image in make_reader(
                            fh, validate_crcs=True,
                            decoder_factories=[DecoderFactory()]).iter_decoded_messages(
                            topics=[IMAGE.topic], starting_at=ns, ending_at=ns):
                        return bytes(image.data)
                return None
            decode = DecoderFactory().decoder_for("cdr", self._schema)
            return bytes(decode(data).data)
        except Exception:  # noqa: BLE001 - the file changed or was damaged under the replay
            return None


def open_recording(path: str | Path) -> Any:
    """What ``relrl replay PATH`` reads: an ``.mcap`` file, a session folder's
    ``session.mcap``, or -- a folder written with ``--out`` alone, or recorded as a folder of
    frames by an earlier relrl -- the folder (:class:`relrl.monitor.replay.Recording`).

    Raises:
        UserError: nothing recorded there, or a bad file.
    """
    p = Path(path)
    if p.is_dir() and (p / "session.mcap").is_symlink():
        raise UserError(f"{p / 'session.mcap'}: a symbolic link; replay reads only what is "
                        "inside the recording, never through a link")
    if p.is_dir() and (p / "session.mcap").is_file():
        p = p / "session.mcap"
    if p.is_dir() or (not p.exists() and p.suffix.lower() != ".mcap"):
        return Recording(p)
    return McapRecording(p)
