"""Image messages as BGR frames: ROS 2's ``sensor_msgs`` and Foxglove's image schemas.

A bag or a recording holds a frame as a message: raw pixels with their width, height, row
step and encoding (``sensor_msgs/msg/Image``, ``foxglove.RawImage``), or a PNG/JPEG file's
bytes with their format (``sensor_msgs/msg/CompressedImage``, ``foxglove.CompressedImage``).
:func:`frame_of` turns any of them into a BGR frame, checking what the message claims before
anything is allocated: a raw frame's size and byte count, a compressed frame's size read from
its PNG/JPEG header (:func:`perception.imagesize.header_size_of`) -- a small message
claiming a huge image is refused without being decoded.

Foxglove's messages come JSON-encoded (``data`` in base64, as Foxglove's JSON schemas say) or
protobuf-encoded (decoded with the ``FileDescriptorSet`` stored as the channel's schema, the
way foxglove-sdk writes them): :func:`foxglove_json` and :class:`ProtobufDecoder` read them
into the same fields.

Every problem is a :class:`~perception.errors.CameraError` of one line naming ``what`` (the
file and topic).
"""

from __future__ import annotations

import base64
import binascii
import json
from typing import Any

import numpy as np

from perception.errors import CameraError, ImageError
from perception.imagesize import check_frame_size, header_size_of

__all__ = ["COMPRESSED", "ENCODINGS", "RAW", "ProtobufDecoder", "fields_of", "foxglove_json",
           "frame_of"]

#: message types of raw frames, and the fields each must have.
RAW = {"sensor_msgs/msg/Image": ("width", "height", "step", "encoding", "data"),
       "sensor_msgs/Image": ("width", "height", "step", "encoding", "data"),
       "foxglove.RawImage": ("width", "height", "step", "encoding", "data")}
#: message types of compressed frames, and the fields each must have.
COMPRESSED = {"sensor_msgs/msg/CompressedImage": ("format", "data"),
              "sensor_msgs/CompressedImage": ("format", "data"),
              "foxglove.CompressedImage": ("format", "data")}

#: raw encodings read, with their channels per pixel.
ENCODINGS = {"rgb8": 3, "bgr8": 3, "8uc3": 3, "rgba8": 4, "bgra8": 4, "mono8": 1, "8uc1": 1,
             "bayer_rggb8": 1, "bayer_bggr8": 1, "bayer_gbrg8": 1, "bayer_grbg8": 1,
             "yuv422": 2, "uyvy": 2, "yuv422_yuy2": 2, "yuyv": 2, "mono16": 1, "16uc1": 1}
_WIDE = ("mono16", "16uc1")


def fields_of(msg: Any, msgtype: str, what: str) -> dict[str, Any]:
    """The fields an image message of type ``msgtype`` must have, read off ``msg`` (an object
    with attributes, or a dict).

    Raises:
        CameraError: a field is missing -- the channel's definition is not its type's (a
            channel named ``Image`` holding ``CompressedImage``'s definition, say).
    """
    names = RAW.get(msgtype) or COMPRESSED[msgtype]
    get = msg.get if isinstance(msg, dict) else lambda k, d: getattr(msg, k, d)
    found: dict[str, Any] = {}
    for name in names + ("is_bigendian",):
        value = get(name, None)
        if value is None and name != "is_bigendian":
            raise CameraError(f"{what}: its messages are typed {msgtype} but have no field "
                              f"{name!r} (the channel's definition is not {msgtype}'s)")
        found[name] = value
    return found


def frame_of(msgtype: str, fields: dict[str, Any], what: str) -> np.ndarray:
    """A BGR frame from an image message's fields (:func:`fields_of`).

    Raises:
        CameraError: an unknown encoding or format, a size outside perception's bounds, too
            few bytes, or bytes that do not decode.
    """
    try:
        if msgtype in COMPRESSED:
            return _compressed(fields, what)
        return _raw(fields, what)
    except ImageError as exc:  # a size out of bounds, a damaged header: named as the bag's
        raise CameraError(str(exc)) from None


def _as_bytes(value: Any, what: str) -> bytes:
    if isinstance(value, bytes | bytearray | memoryview):
        return bytes(value)
    if isinstance(value, np.ndarray) and value.dtype == np.uint8:
        return value.tobytes()
    if isinstance(value, list | tuple) and all(isinstance(v, int) for v in value[:16]):
        try:
            return bytes(value)
        except ValueError:
            pass
    raise CameraError(f"{what}: a frame whose data is not bytes ({type(value).__name__})")


def _int(value: Any, name: str, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise CameraError(f"{what}: a frame whose {name} is not a whole number ({value!r})")
    return int(value)


def _compressed(fields: dict[str, Any], what: str) -> np.ndarray:
    import cv2

    fmt = str(fields["format"]).lower()
    if not ("jpeg" in fmt or "jpg" in fmt or "png" in fmt) or "compresseddepth" in fmt:
        raise CameraError(f"{what}: unknown image format {fields['format']!r} (jpeg and png "
                          "are read)")
    data = _as_bytes(fields["data"], what)
    width, height, kind = header_size_of(data, f"a {fields['format']} frame on {what}")
    if kind not in ("PNG", "JPEG"):
        raise CameraError(f"{what}: a frame said to be {fields['format']!r} holds a {kind} "
                          "image")
    check_frame_size(width, height, f"a frame on {what}")
    level = cv2.utils.logging.getLogLevel()
    cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_ERROR)  # the line below says it
    try:
        frame = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    except cv2.error:
        frame = None
    finally:
        cv2.utils.logging.setLogLevel(level)
    if frame is None or frame.shape[:2] != (height, width):
        raise CameraError(f"{what}: a {fields['format']} frame that cannot be decoded "
                          "(damaged or cut short?)")
    return frame


def _raw(fields: dict[str, Any], what: str) -> np.ndarray:
    import cv2

    encoding = str(fields["encoding"])
    enc = encoding.lower()
    depth = ENCODINGS.get(enc)
    if depth is None:
        raise CameraError(f"{what}: unknown image encoding {encoding!r}; read are "
                          f"{', '.join(sorted(ENCODINGS))}")
    width = _int(fields["width"], "width", what)
    height = _int(fields["height"], "height", what)
    step = _int(fields["step"], "step", what)
    check_frame_size(width, height, f"a frame on {what}")
    size = 2 if enc in _WIDE else 1
    data = np.frombuffer(_as_bytes(fields["data"], what), np.uint8)
    if step < width * depth * size:
        raise CameraError(f"{what}: a {width}x{height} {encoding} frame with rows of step "
                          f"{step} bytes (a row of it is {width * depth * size} bytes)")
    if data.size < step * height:
        raise CameraError(f"{what}: a {width}x{height} {encoding} frame of {data.size} bytes "
                          f"({height} rows of step {step} are {step * height} bytes)")
    rows = data[:step * height].reshape(height, step)[:, :width * depth * size]
    if size == 2:
        dtype = ">u2" if fields.get("is_bigendian") else "<u2"
        raw = rows.copy().view(dtype).reshape(height, width).astype(np.uint16)
        return cv2.cvtColor((raw >> 8).astype(np.uint8), cv2.COLOR_GRAY2BGR)
    raw = np.ascontiguousarray(rows.reshape(height, width, depth) if depth > 1
                               else rows.reshape(height, width))
    conv = {"rgb8": cv2.COLOR_RGB2BGR, "rgba8": cv2.COLOR_RGBA2BGR,
            "bgra8": cv2.COLOR_BGRA2BGR, "mono8": cv2.COLOR_GRAY2BGR,
            "8uc1": cv2.COLOR_GRAY2BGR, "bayer_rggb8": cv2.COLOR_BayerBG2BGR,
            "bayer_bggr8": cv2.COLOR_BayerRG2BGR, "bayer_gbrg8": cv2.COLOR_BayerGR2BGR,
            "bayer_grbg8": cv2.COLOR_BayerGB2BGR, "yuv422": cv2.COLOR_YUV2BGR_UYVY,
            "uyvy": cv2.COLOR_YUV2BGR_UYVY, "yuv422_yuy2": cv2.COLOR_YUV2BGR_YUY2,
            "yuyv": cv2.COLOR_YUV2BGR_YUY2}
    if enc in ("bgr8", "8uc3"):
        return raw
    if enc in ("yuv422", "uyvy", "yuv422_yuy2", "yuyv") and width % 2:
        raise CameraError(f"{what}: a {encoding} frame of odd width {width}")
    return cv2.cvtColor(raw, conv[enc])


def foxglove_json(data: bytes, msgtype: str, what: str) -> dict[str, Any]:
    """A JSON-encoded Foxglove image message's fields (``data`` decoded from base64).

    Raises:
        CameraError: not a JSON object, or ``data`` not base64.
    """
    try:
        msg = json.loads(data)
    except (ValueError, RecursionError):  # UnicodeDecodeError, JSONDecodeError
        raise CameraError(f"{what}: a message that is not JSON") from None
    if not isinstance(msg, dict):
        raise CameraError(f"{what}: a message that is not a JSON object")
    fields = fields_of(msg, msgtype, what)
    if isinstance(fields["data"], str):
        try:
            fields["data"] = base64.b64decode(fields["data"], validate=True)
        except (binascii.Error, ValueError):
            raise CameraError(f"{what}: a frame whose data is not base64") from None
    return fields


class ProtobufDecoder:
    """Decodes a protobuf-encoded channel's messages with the ``FileDescriptorSet`` stored
    as its schema (how MCAP holds protobuf schemas).

    Args:
        msgtype: the message's full name (``foxglove.CompressedImage``).
        schema: the serialized ``FileDescriptorSet``.
        what: names the channel in messages.

    Raises:
        CameraError: the schema is not a descriptor set holding ``msgtype``.
    """

    def __init__(self, msgtype: str, schema: bytes, what: str) -> None:
        try:
            from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
            from google.protobuf.message import DecodeError
        except ImportError:
            raise CameraError(f"{what}: reading protobuf messages needs the protobuf package: "
                              "pip install 'relrl[mcap]'") from None
        self.msgtype, self.what, self._error = msgtype, what, DecodeError
        try:
            files = descriptor_pb2.FileDescriptorSet.FromString(schema)
            pool = descriptor_pool.DescriptorPool()
            for proto in files.file:
                pool.Add(proto)
            self._cls = message_factory.GetMessageClass(pool.FindMessageTypeByName(msgtype))
        except (DecodeError, KeyError, TypeError, ValueError) as exc:
            raise CameraError(f"{what}: its protobuf schema does not define {msgtype} "
                              f"({exc})") from None

    def __call__(self, data: bytes) -> dict[str, Any]:
        """The message's fields.

        Raises:
            CameraError: bytes that are not a message of the schema's type.
        """
        try:
            msg = self._cls.FromString(data)
        except self._error as exc:
            raise CameraError(f"{self.what}: a message that is not a protobuf "
                              f"{self.msgtype} ({exc})") from None
        present = {f.name for f in msg.DESCRIPTOR.fields}
        return fields_of({k: getattr(msg, k) for k in present}, self.msgtype, self.what)
