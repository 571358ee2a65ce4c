"""The channels of a recorded session: one table, used by the MCAP file, the Foxglove server
and the reader.

A time unit of a session (a :class:`~relrl.monitor.view.StepView` row) is split into typed
channels, every field of the row in exactly one of them, so the reader joins them back into
the same row (:func:`split_row`, :func:`join_row`). Standard schemas where robotics has one:

====================================  =================================================  =====
topic                                 schema                                             enc.
====================================  =================================================  =====
``/camera/image/compressed``          ``sensor_msgs/msg/CompressedImage`` (ROS 2)        cdr
``/camera/annotations``               ``foxglove.ImageAnnotations`` (Foxglove)           proto
``/head/joint_states``                ``sensor_msgs/msg/JointState`` (ROS 2)             cdr
``/relrl/percepts`` ...               ``relrl.Percepts`` ... (JSON Schema, below)        json
``/tf``                               ``foxglove.FrameTransforms`` (Foxglove)            proto
``/head/scene``                       ``foxglove.SceneUpdate`` (Foxglove)                proto
``/robot_description``                ``std_msgs/msg/String`` (ROS 2): the head's URDF   cdr
====================================  =================================================  =====

Foxglove's protobuf schemas are foxglove-sdk's own (:mod:`foxglove.messages`), read from it
when a file or the live server needs them (:mod:`relrl.recording.scene` builds the messages).

Every message of one time unit carries the same log time (the session's wall clock when the
unit ended, in nanoseconds) and every JSON message its time unit ``t``: all channels are on
one clock, and the image, its annotations and the unit's percepts line up in Foxglove.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

__all__ = ["CHANNELS", "DESCRIPTION", "ROW_CHANNELS", "SCENE", "TRANSFORMS", "Channel",
           "annotations_of", "cdr_encoders", "encode_row", "join_row", "joint_state_of",
           "split_row", "to_json"]

_TIME = """================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
"""
_HEADER = """================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
""" + _TIME

#: ROS 2 message definitions (the concatenated form rosbag2 writes into a bag's schemas).
ROS2_MSGDEFS = {
    "sensor_msgs/msg/CompressedImage":
        "std_msgs/Header header\nstring format\nuint8[] data\n" + _HEADER,
    "sensor_msgs/msg/Image":
        "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\n"
        "uint8 is_bigendian\nuint32 step\nuint8[] data\n" + _HEADER,
    "sensor_msgs/msg/JointState":
        "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
        "float64[] effort\n" + _HEADER,
    "std_msgs/msg/String": "string data\n",
}

_STR_LIST = {"type": "array", "items": {"type": "string"}}
_T = {"type": "integer", "minimum": 0, "description": "the session's time unit"}


def _object(title: str, description: str, props: dict[str, Any],
            required: tuple[str, ...] = ("t",)) -> dict[str, Any]:
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "title": title,
            "description": description, "type": "object", "properties": props,
            "required": list(required)}


#: JSON Schemas of the JSON channels (relrl's own messages).
JSON_SCHEMAS: dict[str, dict[str, Any]] = {
    "relrl.Session": _object(
        "relrl.Session", "What the session runs: episode, learner, seed, necessities, "
        "responses, where each part runs (sent once, at the start)",
        {"episode": {"type": "string"}, "learner": {"type": ["string", "null"]},
         "seed": {"type": ["integer", "null"]}, "steps": {"type": ["integer", "null"]},
         "necessities": _STR_LIST, "responses": _STR_LIST, "where": {"type": "object"}},
        required=()),
    "relrl.Percepts": _object(
        "relrl.Percepts", "The percepts of one time unit, as Prolog text",
        {"t": _T, "phase": {"type": "string"}, "percepts": _STR_LIST}),
    "relrl.WorkingMemory": _object(
        "relrl.WorkingMemory", "Working memory after the time unit: [age, element] pairs, "
        "youngest first, and the state code",
        {"t": _T, "memory": {"type": ["array", "null"], "items": {
            "type": "array", "prefixItems": [{"type": "integer"}, {"type": "string"}]}},
         "memory_size": {"type": ["integer", "null"]}, "state": {"type": "integer"}}),
    "relrl.Necessities": _object(
        "relrl.Necessities", "Every necessity unit's output and the active necessity",
        {"t": _T, "necessity": {"type": ["string", "null"]},
         "activation": {"type": "object", "additionalProperties": {"type": "number"}}}),
    "relrl.Reward": _object(
        "relrl.Reward", "The reward for the previous response",
        {"t": _T, "reward": {"type": "number"}}),
    "relrl.Response": _object(
        "relrl.Response", "The response chosen, the responses allowed, and the learner's "
        "explanation: the path of tests from the root to the leaf and the ranked actions",
        {"t": _T, "response": {"type": ["string", "null"]}, "allowed": _STR_LIST,
         "explanation": {"type": ["object", "null"], "properties": {
             "path": {"type": "array"}, "actions": {"type": "array"}}}}),
    "relrl.Head": _object(
        "relrl.Head", "The head's commanded pose: per servo the pulse width (us), its offset "
        "from the calibrated centre and a nominal angle; where it looks; clamped commands",
        {"t": _T, "head": {"type": ["object", "null"]}}),
    "relrl.Perception": _object(
        "relrl.Perception", "What perception found in the frame the unit decided on (face "
        "box and pose, the most salient area, its colour and place), the recorded frame's "
        "index and where the head looked when it was seen",
        {"t": _T, "overlay": {"type": ["object", "null"]},
         "frame": {"type": ["integer", "null"]},
         "frame_looking_at": {"type": ["string", "null"]}}),
    "relrl.Interaction": _object(
        "relrl.Interaction", "The rest of the time unit: running CGI and eye contacts, the "
        "caregiver, where the robot looks, words heard and said, naming",
        {"t": _T, "metrics": {"type": "object"}, "caregiver": {},
         "focus": {"type": ["string", "null"]}, "heard": _STR_LIST,
         "naming": {"type": ["string", "null"]}, "said": {"type": ["string", "null"]},
         "unit": {"type": ["integer", "null"]}}),
    "relrl.Tree": _object(
        "relrl.Tree", "The learner's tree whenever it changed: nodes (tests, leaves with "
        "ranked actions) and yes/no edges",
        {"t": _T, "graph": {"type": ["object", "null"], "properties": {
            "nodes": {"type": "array"}, "edges": {"type": "array"}}}}),
    "relrl.Event": _object(
        "relrl.Event", "An evaluation or a naming execution, as it happened",
        {"t": _T, "kind": {"type": "string"}}, required=("t", "kind")),
}


@dataclass(frozen=True)
class Channel:
    """One channel: a topic, its schema and encodings.

    Attributes:
        topic: the topic name.
        schema: the schema's name (a ROS 2 type, a JSON Schema title or a Foxglove
            protobuf message).
        encoding: the message encoding (``cdr``, ``json`` or ``protobuf``).
        keys: the fields of a trace row this channel carries (per-unit channels).
    """

    topic: str
    schema: str
    encoding: str
    keys: tuple[str, ...] = ()

    @property
    def schema_encoding(self) -> str:
        """``ros2msg`` for CDR channels, ``jsonschema`` for JSON ones, ``protobuf`` for
        Foxglove's."""
        return {"cdr": "ros2msg", "protobuf": "protobuf"}.get(self.encoding, "jsonschema")

    @property
    def schema_data(self) -> bytes:
        """The schema: a ROS 2 message definition, a JSON Schema, or foxglove-sdk's
        protobuf ``FileDescriptorSet`` (binary)."""
        if self.encoding == "cdr":
            return ROS2_MSGDEFS[self.schema].encode()
        if self.encoding == "protobuf":
            from foxglove import messages

            return bytes(getattr(messages, self.schema.split(".", 1)[1]).get_schema().data)
        return json.dumps(JSON_SCHEMAS[self.schema], sort_keys=True).encode()


IMAGE = Channel("/camera/image/compressed", "sensor_msgs/msg/CompressedImage", "cdr")
ANNOTATIONS = Channel("/camera/annotations", "foxglove.ImageAnnotations", "protobuf")
JOINTS = Channel("/head/joint_states", "sensor_msgs/msg/JointState", "cdr")
SESSION = Channel("/relrl/session", "relrl.Session", "json")
TREE = Channel("/relrl/tree", "relrl.Tree", "json")
EVENTS = Channel("/relrl/events", "relrl.Event", "json")
TRANSFORMS = Channel("/tf", "foxglove.FrameTransforms", "protobuf")
SCENE = Channel("/head/scene", "foxglove.SceneUpdate", "protobuf")
DESCRIPTION = Channel("/robot_description", "std_msgs/msg/String", "cdr")

#: the per-time-unit channels and the trace-row fields each carries (``t`` goes in all).
ROW_CHANNELS: tuple[Channel, ...] = (
    Channel("/relrl/percepts", "relrl.Percepts", "json", ("phase", "percepts")),
    Channel("/relrl/working_memory", "relrl.WorkingMemory", "json",
            ("memory", "memory_size", "state")),
    Channel("/relrl/necessities", "relrl.Necessities", "json", ("necessity", "activation")),
    Channel("/relrl/reward", "relrl.Reward", "json", ("reward",)),
    Channel("/relrl/response", "relrl.Response", "json", ("response", "allowed",
                                                           "explanation")),
    Channel("/relrl/head", "relrl.Head", "json", ("head",)),
    Channel("/relrl/perception", "relrl.Perception", "json",
            ("overlay", "frame", "frame_looking_at")),
    # the rest of the row, whatever the session adds (caregiver, focus, heard, ...)
    Channel("/relrl/interaction", "relrl.Interaction", "json", ()),
)
_REST = ROW_CHANNELS[-1]
PERCEPTION = ROW_CHANNELS[-2]
_KNOWN = {"t"} | {k for ch in ROW_CHANNELS for k in ch.keys}

#: every channel, in the order they are registered.
CHANNELS: tuple[Channel, ...] = (SESSION, *ROW_CHANNELS, IMAGE, ANNOTATIONS, JOINTS, TREE,
                                 EVENTS, TRANSFORMS, SCENE, DESCRIPTION)


def split_row(row: dict[str, Any]) -> list[tuple[Channel, dict[str, Any]]]:
    """A trace row as one message per per-unit channel (each with the row's ``t``).

    The head channel is left out when the row has no head; every other field of the row is
    in exactly one message, so :func:`join_row` gives the row back.
    """
    t = row["t"]
    out = []
    for ch in ROW_CHANNELS[:-1]:
        if ch.keys == ("head",) and row.get("head") is None:
            continue
        msg = {"t": t}
        for k in ch.keys:
            if k in row:
                msg[k] = row[k]
        out.append((ch, msg))
    rest = {"t": t}
    rest.update((k, v) for k, v in row.items() if k not in _KNOWN)
    out.append((_REST, rest))
    return out


_ENCODE = json.JSONEncoder(separators=(",", ":"), allow_nan=False, default=str).encode


def _finite(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def to_json(msg: dict[str, Any]) -> bytes:
    """A message as compact JSON bytes (non-finite numbers as ``null``: JSON has none)."""
    try:
        return _ENCODE(msg).encode()
    except ValueError:
        return _ENCODE(_finite(msg)).encode()


def encode_row(row: dict[str, Any]) -> list[tuple[Channel, bytes]]:
    """:func:`split_row`, each message encoded as JSON."""
    return [(ch, to_json(msg)) for ch, msg in split_row(row)]


def join_row(parts: list[dict[str, Any]]) -> dict[str, Any]:
    """The messages of one time unit merged back into a trace row."""
    row: dict[str, Any] = {}
    for part in parts:
        row.update(part)
    row.setdefault("head", None)
    return row


def _color(r: float, g: float, b: float, a: float = 1.0) -> dict[str, float]:
    return {"r": r, "g": g, "b": b, "a": a}


def _box(box: list[int], stamp: dict[str, int], color: dict[str, float]) -> dict[str, Any]:
    x, y, w, h = box
    return {"timestamp": stamp, "type": 2, "thickness": 2.0, "outline_color": color,
            "outline_colors": [], "fill_color": _color(0, 0, 0, 0),
            "points": [{"x": float(px), "y": float(py)}
                       for px, py in ((x, y), (x + w, y), (x + w, y + h), (x, y + h))]}


def _label(x: float, y: float, text: str, stamp: dict[str, int],
           color: dict[str, float]) -> dict[str, Any]:
    return {"timestamp": stamp, "position": {"x": float(x), "y": float(max(y, 12))},
            "text": text, "font_size": 12.0, "text_color": color,
            "background_color": _color(0, 0, 0, 0.6)}


def annotations_of(overlay: dict[str, Any] | None, ns: int) -> dict[str, Any]:
    """What perception found in a frame as the fields of a ``foxglove.ImageAnnotations``
    message (:func:`relrl.recording.scene.encode_annotations` encodes them): the face box with
    its pose, the most salient area's box with its colour and place, and a cross on its
    saliency peak (the same drawing as the monitor's page)."""
    stamp = {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}
    points: list[dict[str, Any]] = []
    texts: list[dict[str, Any]] = []
    face = (overlay or {}).get("face")
    if face:
        green = _color(0.2, 0.9, 0.3)
        points.append(_box(face["box"], stamp, green))
        texts.append(_label(face["box"][0], face["box"][1] - 4,
                            f"face {face['pose']} (pan {face['pan']}, tilt {face['tilt']})",
                            stamp, green))
    obj = (overlay or {}).get("object")
    if obj:
        yellow, red = _color(1.0, 0.85, 0.1), _color(1.0, 0.1, 0.1)
        points.append(_box(obj["box"], stamp, yellow))
        px, py = obj["peak"]
        points.append({"timestamp": stamp, "type": 4, "thickness": 2.0, "outline_color": red,
                       "outline_colors": [], "fill_color": _color(0, 0, 0, 0),
                       "points": [{"x": px - 5.0, "y": float(py)},
                                  {"x": px + 5.0, "y": float(py)},
                                  {"x": float(px), "y": py - 5.0},
                                  {"x": float(px), "y": py + 5.0}]})
        texts.append(_label(obj["box"][0], obj["box"][1] - 4,
                            f"{obj.get('colour') or 'object'} at {obj.get('place')} "
                            f"(saliency {obj.get('saliency')})", stamp, yellow))
    return {"circles": [], "points": points, "texts": texts}


def joint_state_of(head: dict[str, Any], ns: int) -> dict[str, Any]:
    """The head's commanded pose as a ``sensor_msgs/msg/JointState`` message: one joint per
    servo, its position in radians from the calibrated centre (the nominal angle the monitor
    shows; the pulse widths themselves are on ``/relrl/head``)."""
    servos = head.get("servos") or {}
    names = sorted(servos)
    return {"header": {"stamp": {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000},
                       "frame_id": "head"},
            "name": names,
            "position": [math.radians(float(servos[n]["deg"])) for n in names],
            "velocity": [], "effort": []}


def cdr_encoders() -> dict[str, Any]:
    """Topic -> ROS 2 CDR encoder (a message as a dict -> bytes) of the CDR channels, built
    by mcap-ros2-support from the definitions above (the ``mcap`` extra)."""
    from mcap_ros2._dynamic import serialize_dynamic  # its writer's own encoder factory

    return {ch.topic: serialize_dynamic(ch.schema, ch.schema_data.decode())[ch.schema]
            for ch in CHANNELS if ch.encoding == "cdr"}
