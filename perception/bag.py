"""A robot's ROS 2 bag (MCAP) as a camera: ``--camera BAG.mcap[:TOPIC]``.

:class:`BagCamera` reads the ``sensor_msgs/msg/Image`` or ``sensor_msgs/msg/CompressedImage``
messages of one topic of an MCAP file -- a ROS 2 bag (the default storage since Iron) or a
session relrl recorded -- without ROS: the ``mcap`` and ``mcap-ros2-support`` packages
decode the CDR messages with the message definitions stored in the bag.

Frames come at their recorded times (``paced``, the default for a session): the first read
starts the bag's clock; each read returns the newest frame whose log time has come on that
clock, waits for the next one when the robot is faster than the camera was, and skips the
frames a slower robot missed -- what a live camera would have given. ``paced=False`` returns
every frame in order (``relrl perceive BAG.mcap``). :attr:`BagCamera.stamp` is the log time
(nanoseconds) of the frame read last.

Image encodings: ``rgb8``, ``bgr8``, ``rgba8``, ``bgra8``, ``mono8``, ``mono16``, ``8UC1``,
``8UC3``, ``16UC1``, the four 8-bit Bayer patterns, ``yuv422``/``uyvy`` and
``yuv422_yuy2``/``yuyv``; compressed ``jpeg`` and ``png``. A file that is not MCAP, is cut
short (no summary at its end), has no image topic, names a topic it does not have, or holds
frames in another encoding is a :class:`~perception.errors.CameraError` naming the file.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from perception.errors import CameraError
from perception.imagesize import check_frame_size
from perception.source import Camera

__all__ = ["IMAGE_TYPES", "BagCamera", "parse_bag_source"]

#: the message types read as camera frames (ROS 2 names, and their ROS 1 style short names).
IMAGE_TYPES = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage",
               "sensor_msgs/Image", "sensor_msgs/CompressedImage")
_MAGIC = b"\x89MCAP0\r\n"


def parse_bag_source(source: str) -> tuple[str, str | None]:
    """``BAG.mcap[:TOPIC]`` -> ``(path, topic or None)``."""
    path, sep, topic = source.partition(".mcap:")
    if sep:
        return path + ".mcap", topic or None
    return source, None


def _bgr(cv2: Any, raw: np.ndarray, encoding: str) -> np.ndarray | None:
    """A decoded raw frame (``rows x step`` bytes reshaped by the caller) as BGR."""
    conv = {"rgb8": cv2.COLOR_RGB2BGR, "rgba8": cv2.COLOR_RGBA2BGR,
            "bgra8": cv2.COLOR_BGRA2BGR, "mono8": cv2.COLOR_GRAY2BGR,
            "8uc1": cv2.COLOR_GRAY2BGR, "bayer_rggb8": cv2.COLOR_BayerBG2BGR,
            "bayer_bggr8": cv2.COLOR_BayerRG2BGR, "bayer_gbrg8": cv2.COLOR_BayerGR2BGR,
            "bayer_grbg8": cv2.COLOR_BayerGB2BGR, "yuv422": cv2.COLOR_YUV2BGR_UYVY,
            "uyvy": cv2.COLOR_YUV2BGR_UYVY, "yuv422_yuy2": cv2.COLOR_YUV2BGR_YUY2,
            "yuyv": cv2.COLOR_YUV2BGR_YUY2}
    if encoding in ("bgr8", "8uc3"):
        return raw
    if encoding in conv:
        return cv2.cvtColor(raw, conv[encoding])
    if encoding in ("mono16", "16uc1"):
        return cv2.cvtColor((raw >> 8).astype(np.uint8), cv2.COLOR_GRAY2BGR)
    return None


_CHANNELS = {"rgb8": 3, "bgr8": 3, "8uc3": 3, "rgba8": 4, "bgra8": 4, "mono8": 1, "8uc1": 1,
             "bayer_rggb8": 1, "bayer_bggr8": 1, "bayer_gbrg8": 1, "bayer_grbg8": 1,
             "yuv422": 2, "uyvy": 2, "yuv422_yuy2": 2, "yuyv": 2, "mono16": 1, "16uc1": 1}


class BagCamera(Camera):
    """The image messages of one topic of an MCAP file, as a camera.

    Args:
        path: the ``.mcap`` file.
        topic: the image topic (default: the file's only image topic).
        paced: frames at their recorded times (else every frame, in order).

    Raises:
        CameraError: not an MCAP file, cut short, no (such) image topic.
    """

    def __init__(self, path: str | Path, topic: str | None = None, *, paced: bool = True) -> None:
        super().__init__()
        self.path = Path(path)
        self.paced = paced
        self.stamp: int | None = None
        self._fh = None
        if not self.path.is_file():
            raise CameraError(f"no such bag file: {str(path)!r}")
        try:
            import mcap  # noqa: F401
            import mcap_ros2  # noqa: F401
        except ImportError:
            raise CameraError(f"{path}: reading a bag needs the mcap and mcap-ros2-support "
                              "packages: pip install 'relrl[mcap]'") from None
        self._fh = open(self.path, "rb")  # noqa: SIM115 - closed by _release
        try:
            self.topic, self.type, self.count = self._choose(topic)
            self._messages = self._iter()
        except BaseException:
            self._fh.close()
            self._closed = True
            raise
        self.name = f"bag {self.path}:{self.topic}"
        self._start: tuple[float, int] | None = None
        self._pending: Any = None
        self.read_count = 0
        self.skipped = 0

    def _fail(self, why: str) -> CameraError:
        return CameraError(f"{self.path}: {why}")

    def _choose(self, topic: str | None) -> tuple[str, str, int]:
        from mcap.reader import make_reader

        if self._fh.read(8) != _MAGIC:
            raise self._fail("not an MCAP file (a ROS 2 bag is a .mcap file; convert a "
                             "sqlite3 bag with `ros2 bag convert`)")
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
        images = {t: v for t, v in found.items() if v[0] in IMAGE_TYPES}
        if topic is not None:
            if topic not in found:
                raise self._fail(f"no topic {topic!r}; its image topics: "
                                 f"{', '.join(sorted(images)) or 'none'}")
            if topic not in images:
                raise self._fail(f"topic {topic} holds {found[topic][0]}, not images "
                                 "(sensor_msgs/msg/Image or CompressedImage)")
        elif not images:
            listed = ", ".join(f"{t} ({v[0]})" for t, v in sorted(found.items())) or "none"
            raise self._fail(f"no image topic (sensor_msgs/msg/Image or CompressedImage); "
                             f"its topics: {listed}")
        elif len(images) > 1:
            raise self._fail(f"several image topics ({', '.join(sorted(images))}); choose "
                             f"one: --camera {self.path}:TOPIC")
        else:
            topic = next(iter(images))
        name, encoding, count = images[topic]
        if encoding != "cdr":
            raise self._fail(f"topic {topic} is encoded as {encoding!r}, not ROS 2 CDR")
        return topic, name, count

    def _iter(self) -> Any:
        from mcap.reader import make_reader
        from mcap_ros2.decoder import DecoderFactory

        self._decoders = DecoderFactory()  # one per bag: it keeps each schema's decoder
        self._fh.seek(0)
        reader = make_reader(self._fh, validate_crcs=True,
                             decoder_factories=[DecoderFactory()])
        return reader.iter_messages(topics=[self.topic])

    def _next_message(self) -> Any:

        try:
            return next(self._messages, None)
        except Exception as exc:  # noqa: BLE001 - a CRC, zstd/lz4 or record error: damage
            raise self._fail(f"damaged MCAP file ({exc})") from None

    def _decode(self, schema: Any, message: Any) -> np.ndarray:
        import cv2
        from mcap_ros2.decoder import DecoderFactory

        try:
            decoder = DecoderFactory().decoder_for("cdr", schema)
            msg = decoder(message.data)
        except Exception as exc:  # noqa: BLE001 - the message's bytes do not fit its schema
            raise self._fail(f"a message on {self.topic} cannot be decoded as "
                             f"{schema.name} ({exc})") from None
        if "Compressed" in schema.name:
            fmt = str(msg.format).lower()
            if not ("jpeg" in fmt or "jpg" in fmt or "png" in fmt) or "compresseddepth" in fmt:
                raise self._fail(f"{self.topic}: unknown image format {msg.format!r} (jpeg "
                                 "and png are read)")
            frame = cv2.imdecode(np.frombuffer(bytes(msg.data), np.uint8), cv2.IMREAD_COLOR)
            if frame is None:
                raise self._fail(f"{self.topic}: a {msg.format} frame that cannot be decoded")
        else:
            enc = str(msg.encoding).lower()
            depth = _CHANNELS.get(enc)
            if depth is None:
                raise self._fail(f"{self.topic}: unknown image encoding {msg.encoding!r}; "
                                 f"read are {', '.join(sorted(_CHANNELS))}")
            width, height, step = int(msg.width), int(msg.height), int(msg.step)
            check_frame_size(width, height, f"{self.path}:{self.topic}")
            size = 2 if enc in ("mono16", "16uc1") else 1
            data = np.frombuffer(bytes(msg.data), np.uint8)
            if step < width * depth * size or data.size < step * height:
                raise self._fail(f"{self.topic}: a {width}x{height} {msg.encoding} frame "
                                 f"with {data.size} bytes (step {step})")
            rows = data[:step * height].reshape(height, step)[:, :width * depth * size]
            if size == 2:
                dtype = ">u2" if int(msg.is_bigendian) else "<u2"
                raw = rows.copy().view(dtype).reshape(height, width).astype(np.uint16)
            else:
                raw = rows.reshape(height, width, depth) if depth > 1 else \
                    rows.reshape(height, width)
            frame = _bgr(cv2, np.ascontiguousarray(raw), enc)
        check_frame_size(frame.shape[1], frame.shape[0], f"{self.path}:{self.topic}")
        return frame

    def read(self) -> np.ndarray | None:
        """The next frame (at its recorded time when paced), or ``None`` at the bag's end."""
        if self._closed:
            return None
        item = self._pending or self._next_message()
        self._pending = None
        if item is None:
            return None
        if self.paced:
            now = time.monotonic()
            if self._start is None:
                self._start = (now, item[2].log_time)
            else:
                due = lambda msg: self._start[0] + (msg.log_time - self._start[1]) / 1e9  # noqa: E731
                while True:  # skip what a slower robot missed; wait for what is to come
                    following = self._next_message()
                    if following is None or due(following[2]) > now:
                        self._pending = following
                        break
                    item = following
                    self.skipped += 1
                wait = due(item[2]) - time.monotonic()
                if wait > 0:
                    time.sleep(wait)
        schema, _, message = item
        self.stamp = message.log_time
        self.read_count += 1
        return self._decode(schema, message)

    def _release(self) -> None:
        if self._fh is not None:
            self._fh.close()
