"""A robot's bag as a camera: ``--camera BAG[:TOPIC]`` for ``BAG.mcap``, ``BAG.db3`` or a
rosbag2 folder.

:class:`BagCamera` reads the image messages of one topic -- ROS 2's
``sensor_msgs/msg/Image`` and ``CompressedImage`` (CDR), Foxglove's ``foxglove.RawImage``
and ``foxglove.CompressedImage`` (JSON or protobuf) -- without ROS:

* an MCAP file (a ROS 2 bag, the default storage since Iron; a file a Foxglove SDK wrote; a
  session relrl recorded) through the ``mcap`` library, chunk CRCs checked; CDR messages
  decoded by ``mcap-ros2-support`` with the definitions stored in the file, protobuf ones
  with the stored ``FileDescriptorSet``;
* a SQLite ``.db3`` bag, or a rosbag2 folder (its ``metadata.yaml`` and storage files), through
  ``rosbags``, with the definitions the bag stores (a bag from before Iron stores none: then
  ROS 2's own ``sensor_msgs`` definitions).

Frames come at their recorded times (``paced``, the default for a session): the first read
starts the bag's clock; each read returns the newest frame whose log time has come on that
clock, waits for the next one when the robot is faster than the camera was, and skips the
frames a slower robot missed -- what a live camera would have given. ``paced=False`` returns
every frame in order (``relrl perceive BAG``). :attr:`BagCamera.stamp` is the log time
(nanoseconds) of the frame read last; :attr:`BagCamera.ended` is true once the bag has no
more frames.

Every way a bag can be wrong -- not a bag, cut short, damaged, no (such) image topic, a
channel whose definition is not its type's, an unknown encoding, a frame larger than
perception's bounds (read from the PNG/JPEG header, before decoding) -- is a
:class:`~perception.errors.CameraError` of one line naming the file.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from perception.errors import CameraError
from perception.imagemsg import (
    COMPRESSED,
    RAW,
    ProtobufDecoder,
    fields_of,
    foxglove_json,
    frame_of,
)
from perception.source import Camera

__all__ = ["BAG_SUFFIXES", "IMAGE_TYPES", "BagCamera", "is_bag", "parse_bag_source"]

#: the message types read as camera frames.
IMAGE_TYPES = tuple(RAW) + tuple(COMPRESSED)
#: the files read as bags (a rosbag2 folder is one too: :func:`is_bag`).
BAG_SUFFIXES = (".mcap", ".db3")
_MAGIC = b"\x89MCAP0\r\n"
_ROS_ENCODING = "cdr"
_FOXGLOVE_ENCODINGS = ("json", "protobuf")


def parse_bag_source(source: str) -> tuple[str, str | None]:
    """``BAG.mcap[:TOPIC]``, ``BAG.db3[:TOPIC]`` or ``FOLDER[:TOPIC]`` -> ``(path, topic or
    None)`` (a topic starts with ``/``)."""
    for suffix in BAG_SUFFIXES:
        path, sep, topic = source.partition(suffix + ":")
        if sep:
            return path + suffix, topic or None
    path, sep, topic = source.partition(":/")
    if sep and Path(path).is_dir():
        return path, "/" + topic
    return source, None


def is_bag(source: str) -> bool:
    """Whether ``source`` names a bag (:func:`parse_bag_source`): an ``.mcap`` or ``.db3``
    file, or a rosbag2 folder (one with a ``metadata.yaml``)."""
    path, _ = parse_bag_source(source)
    if path.lower().endswith(BAG_SUFFIXES):
        return True
    return Path(path).is_dir() and (Path(path) / "metadata.yaml").is_file()


class _Item(NamedTuple):
    log_time: int
    data: bytes
    decode: Callable[[bytes], dict[str, Any]]


class BagCamera(Camera):
    """The image messages of one topic of a bag, as a camera.

    Args:
        path: the ``.mcap`` or ``.db3`` file, or a rosbag2 folder.
        topic: the image topic (default: the bag's only image topic).
        paced: frames at their recorded times (else every frame, in order).

    Raises:
        CameraError: not a bag, cut short, no (such) image topic.
    """

    def __init__(self, path: str | Path, topic: str | None = None, *, paced: bool = True) -> None:
        super().__init__()
        self.path = Path(path)
        self.paced = paced
        self.stamp: int | None = None
        self.first_stamp: int | None = None
        self.ended = False
        self._fh: Any = None
        self._rosbag: Any = None
        self._db3_decode: Callable[[bytes], dict[str, Any]] | None = None
        if self.path.is_dir() and not (self.path / "metadata.yaml").is_file():
            raise CameraError(f"{str(path)!r} is a folder without a metadata.yaml, not a "
                              "rosbag2 bag")
        if self.path.exists() and not (self.path.is_file() or self.path.is_dir()):
            raise CameraError(f"{str(path)!r} is not a regular file (a device or a pipe?)")
        if not self.path.exists():
            raise CameraError(f"no such bag file: {str(path)!r}")
        try:
            if self.path.is_file() and self.path.suffix.lower() != ".db3":
                self.topic, self.type, self.count = self._open_mcap(topic)
            else:
                self.topic, self.type, self.count = self._open_rosbag(topic)
        except BaseException:
            self._release()
            self._closed = True
            raise
        self.what = f"{self.path}:{self.topic}"
        self.name = f"bag {self.what}"
        self._start: tuple[float, int] | None = None
        self._pending: _Item | None = None
        self.read_count = 0
        self.skipped = 0

    def _fail(self, why: str) -> CameraError:
        return CameraError(f"{self.path}: {why}")

    def _pick(self, found: dict[str, tuple[str, str, int]], topic: str | None
              ) -> tuple[str, str, int]:
        """The image topic to read, from ``{topic: (type, encoding, count)}``."""
        images = {t: v for t, v in found.items() if v[0] in IMAGE_TYPES}
        kinds = "sensor_msgs/msg/Image or CompressedImage, foxglove.RawImage or CompressedImage"
        if topic is not None:
            if topic not in found:
                raise self._fail(f"no topic {topic!r}; its image topics: "
                                 f"{', '.join(sorted(images)) or 'none'}")
            if topic not in images:
                raise self._fail(f"topic {topic} holds {found[topic][0]}, not images ({kinds})")
        elif not images:
            listed = ", ".join(f"{t} ({v[0]})" for t, v in sorted(found.items())) or "none"
            raise self._fail(f"no image topic ({kinds}); its topics: {listed}")
        elif len(images) > 1:
            raise self._fail(f"several image topics ({', '.join(sorted(images))}); choose "
                             f"one: --camera {self.path}:TOPIC")
        else:
            topic = next(iter(images))
        name, encoding, count = images[topic]
        wanted = _FOXGLOVE_ENCODINGS if name.startswith("foxglove.") else (_ROS_ENCODING,)
        if encoding not in wanted:
            raise self._fail(f"topic {topic} ({name}) is encoded as {encoding!r}, not "
                             f"{' or '.join(wanted)}")
        return topic, name, count

    # ---- MCAP, through the mcap library ---------------------------------------------------

    def _open_mcap(self, topic: str | None) -> tuple[str, str, int]:
        try:
            import mcap  # noqa: F401
            import mcap_ros2  # noqa: F401
        except ImportError:
            raise self._fail("reading an MCAP bag needs the mcap and mcap-ros2-support "
                             "packages: pip install 'relrl[mcap]'") from None
        from mcap.reader import make_reader

        self._fh = open(self.path, "rb")  # noqa: SIM115 - closed by _release
        if self._fh.read(8) != _MAGIC:
            raise self._fail("not an MCAP file or a ROS 2 bag (.mcap, .db3, or a rosbag2 "
                             "folder; convert a ROS 1 .bag with `rosbags-convert`)")
        self._fh.seek(-8, 2)
        if self._fh.read(8) != _MAGIC:
            raise self._fail("cut short (no summary at its end: was the recorder killed?); "
                             "`mcap recover` writes a readable copy")
        self._fh.seek(0)
        try:
            summary = make_reader(self._fh).get_summary()
        except Exception as exc:  # noqa: BLE001 - only the file's bytes are read here
            raise self._fail(f"damaged MCAP file ({exc})") from None
        if summary is None:
            raise self._fail("no summary (an MCAP file written without one cannot be played "
                             "at its recorded times; `mcap recover` writes one)")
        counts = summary.statistics.channel_message_counts if summary.statistics else {}
        found = {}
        for cid, ch in summary.channels.items():
            schema = summary.schemas.get(ch.schema_id)
            name = schema.name if schema is not None else "(no schema)"
            found[ch.topic] = (name, ch.message_encoding, counts.get(cid, 0))
        chosen = self._pick(found, topic)
        self._decoders: dict[int, Callable[[bytes], dict[str, Any]]] = {}
        self._fh.seek(0)
        self._messages: Iterator[Any] = make_reader(self._fh, validate_crcs=True).iter_messages(
            topics=[chosen[0]])
        return chosen

    def _mcap_decoder(self, schema: Any, channel: Any) -> Callable[[bytes], dict[str, Any]]:
        """The decoder of a channel's messages into an image message's fields."""
        what = f"{self.path}:{channel.topic}"
        if schema is None or schema.name not in IMAGE_TYPES:
            raise self._fail(f"topic {channel.topic} has a channel that is not images")
        name = schema.name
        if channel.message_encoding == "json":
            return lambda data: foxglove_json(data, name, what)
        if channel.message_encoding == "protobuf":
            return ProtobufDecoder(name, bytes(schema.data), what)
        from mcap_ros2.decoder import DecoderFactory

        try:
            decode = DecoderFactory().decoder_for(channel.message_encoding, schema)
        except Exception as exc:  # noqa: BLE001 - the stored definition does not parse
            raise self._fail(f"topic {channel.topic}: its {name} definition cannot be read "
                             f"({type(exc).__name__}: {exc})") from None

        def fields(data: bytes) -> dict[str, Any]:
            try:
                msg = decode(data)
            except Exception as exc:  # noqa: BLE001 - the bytes do not fit the definition
                raise CameraError(f"{what}: a message that cannot be decoded as {name} "
                                  f"({type(exc).__name__}: {exc})") from None
            return fields_of(msg, name, what)

        return fields

    def _next_mcap(self) -> _Item | None:
        try:
            item = next(self._messages, None)
        except Exception as exc:  # noqa: BLE001 - a CRC, zstd/lz4 or record error: damage
            raise self._fail(f"damaged MCAP file ({type(exc).__name__}: {exc})") from None
        if item is None:
            return None
        schema, channel, message = item
        decode = self._decoders.get(channel.id)
        if decode is None:
            decode = self._decoders[channel.id] = self._mcap_decoder(schema, channel)
        return _Item(message.log_time, message.data, decode)

    # ---- .db3 and rosbag2 folders, through rosbags ----------------------------------------

    def _open_rosbag(self, topic: str | None) -> tuple[str, str, int]:
        try:
            from rosbags.rosbag2 import Reader
            from rosbags.typesys import Stores, get_types_from_msg, get_typestore
        except ImportError:
            raise self._fail("reading a .db3 bag needs the rosbags package: pip install "
                             "'relrl[mcap]'") from None
        try:
            self._rosbag = Reader(self.path)
            self._rosbag.open()
            connections = list(self._rosbag.connections)
        except Exception as exc:  # noqa: BLE001 - SQLite's, YAML's or rosbags' errors on
            # the file's bytes: the bag is not readable
            raise self._fail(f"not a readable ROS 2 bag ({type(exc).__name__}: "
                             f"{str(exc).splitlines()[0] if str(exc) else 'no reason'})") \
                from None
        found: dict[str, tuple[str, str, int]] = {}
        for c in connections:
            count = found.get(c.topic, ("", "", 0))[2]
            found[c.topic] = (c.msgtype, getattr(c.ext, "serialization_format", "cdr"),
                              count + c.msgcount)
        chosen = self._pick(found, topic)
        conns = [c for c in connections if c.topic == chosen[0]]
        store = get_typestore(Stores.EMPTY)
        for c in conns:
            if not c.msgdef.data:  # a bag from before Iron: ROS 2's own definitions
                store = get_typestore(Stores.ROS2_HUMBLE)
                break
            try:
                store.register(get_types_from_msg(c.msgdef.data, c.msgtype))
            except Exception as exc:  # noqa: BLE001 - a stored definition that does not parse
                raise self._fail(f"topic {chosen[0]}: its {c.msgtype} definition cannot be "
                                 f"read ({type(exc).__name__}: {exc})") from None
        what = f"{self.path}:{chosen[0]}"
        hint = ""
        if self.path.is_file() and (self.path.parent / "metadata.yaml").is_file():
            hint = (f"; if the bag compresses each message, give its folder "
                    f"{self.path.parent} (its metadata.yaml says so)")

        def fields(data: bytes) -> dict[str, Any]:
            try:
                msg = store.deserialize_cdr(data, chosen[1])
            except Exception as exc:  # noqa: BLE001 - the bytes do not fit the definition
                raise CameraError(f"{what}: a message that cannot be decoded as {chosen[1]} "
                                  f"({type(exc).__name__}: {exc}){hint}") from None
            return fields_of(msg, chosen[1], what)

        self._db3_decode = fields
        self._messages = self._rosbag.messages(connections=conns)
        return chosen

    def _next_rosbag(self) -> _Item | None:
        try:
            item = next(self._messages, None)
        except Exception as exc:  # noqa: BLE001 - SQLite or storage errors: damage
            raise self._fail(f"damaged bag ({type(exc).__name__}: {exc})") from None
        if item is None:
            return None
        _, timestamp, data = item
        return _Item(timestamp, bytes(data), self._db3_decode)

    # ---- reading ---------------------------------------------------------------------------

    def _next_message(self) -> _Item | None:
        return self._next_rosbag() if self._db3_decode is not None else self._next_mcap()

    def read(self) -> np.ndarray | None:
        """The next frame (at its recorded time when paced), or ``None`` at the bag's end."""
        if self._closed:
            return None
        item = self._pending or self._next_message()
        self._pending = None
        if item is None:
            self.ended = True
            return None
        if self.paced:
            now = time.monotonic()
            if self._start is None:
                self._start = (now, item.log_time)
            else:
                start = self._start

                def due(msg: _Item) -> float:
                    return start[0] + (msg.log_time - start[1]) / 1e9

                while True:  # skip what a slower robot missed; wait for what is to come
                    following = self._next_message()
                    if following is None or due(following) > now:
                        self._pending = following
                        break
                    item = following
                    self.skipped += 1
                wait = due(item) - time.monotonic()
                if wait > 0:
                    time.sleep(wait)
        self.stamp = item.log_time
        if self.first_stamp is None:
            self.first_stamp = item.log_time
        self.read_count += 1
        return frame_of(self.type, item.decode(item.data), self.what)

    @property
    def seconds(self) -> float:
        """Seconds of the bag played: from its first frame to the frame read last."""
        if self.stamp is None or self.first_stamp is None:
            return 0.0
        return (self.stamp - self.first_stamp) / 1e9

    def _release(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None
        if self._rosbag is not None:
            if self._rosbag.is_open:
                self._rosbag.close()
            self._rosbag = None
