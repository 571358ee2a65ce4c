"""What a session produced, as the messages of its channels (one encoder for the file and for
Foxglove).

:class:`Encoder` turns a time unit's trace row (and its JPEG frame) into the messages of
:mod:`relrl.recording.channels`: the row's per-unit JSON channels, the head's joint states
(ROS 2 CDR), the camera image (ROS 2 CompressedImage, CDR) and what perception found in it
(Foxglove ImageAnnotations, JSON), and the head in 3D (:mod:`relrl.recording.scene`: its
frames, its gaze and the caregiver's face, Foxglove's protobuf messages). Every message of a
unit gets the unit's log time.
"""

from __future__ import annotations

from typing import Any

from relrl.recording.channels import (
    ANNOTATIONS,
    DESCRIPTION,
    EVENTS,
    IMAGE,
    JOINTS,
    PERCEPTION,
    SCENE,
    SESSION,
    TRANSFORMS,
    TREE,
    Channel,
    annotations_of,
    cdr_encoders,
    encode_row,
    joint_state_of,
    to_json,
)
from relrl.recording.scene import SceneEncoder, encode_annotations

__all__ = ["Encoder", "Message"]

#: one encoded message: its channel, its log time (ns) and its bytes.
Message = tuple[Channel, int, bytes]


class Encoder:
    """Encode a session's time units, frames, tree, events (mcap-ros2-support for CDR,
    foxglove-sdk for Foxglove's protobuf messages).

    Args:
        urdf: the head's robot description (default: the shipped WHA-8030's).
    """

    def __init__(self, urdf: str | None = None) -> None:

        self._cdr = cdr_encoders()
        self._scene = SceneEncoder(urdf)

    def unit(self, ns: int, row: dict[str, Any], jpeg: bytes | None = None) -> list[Message]:
        """A time unit's messages; ``jpeg``: its frame, when one was recorded."""
        out = [(ch, ns, data) for ch, data in encode_row(row)]
        head = row.get("head")
        if head:
            joints = joint_state_of(head, ns)
            out.append((JOINTS, ns, self._cdr[JOINTS.topic](joints)))
            positions = dict(zip(joints["name"], joints["position"], strict=True))
            out.append((TRANSFORMS, ns, self._scene.transforms(ns, positions)))
            out.append((SCENE, ns, self._scene.scene(ns, row.get("overlay"))))
        if jpeg:
            out += self.image(ns, jpeg, row.get("overlay"))
        return out

    def image(self, ns: int, jpeg: bytes, overlay: dict[str, Any] | None) -> list[Message]:
        """A JPEG frame and its annotations."""
        stamp = {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}
        return [(IMAGE, ns, self._cdr[IMAGE.topic](
                    {"header": {"stamp": stamp, "frame_id": "camera"}, "format": "jpeg",
                     "data": jpeg})),
                (ANNOTATIONS, ns, encode_annotations(annotations_of(overlay, ns)))]

    def last_frame(self, ns: int, msg: dict[str, Any], jpeg: bytes) -> list[Message]:
        """A frame after the last unit: ``msg`` is its perception message (``t``,
        ``overlay``, ``frame``, ``frame_looking_at``)."""
        return [(PERCEPTION, ns, to_json(msg)), *self.image(ns, jpeg, msg.get("overlay"))]

    def session(self, ns: int, info: dict[str, Any]) -> list[Message]:
        """What the session runs, and the head's robot description."""
        return [(SESSION, ns, to_json(info)),
                (DESCRIPTION, ns, self._cdr[DESCRIPTION.topic](
                    {"data": self._scene.description}))]

    @staticmethod
    def tree(ns: int, msg: dict[str, Any]) -> list[Message]:
        """The tree (``{"t", "graph"}``)."""
        return [(TREE, ns, to_json(msg))]

    @staticmethod
    def event(ns: int, msg: dict[str, Any]) -> list[Message]:
        """An evaluation or naming execution (``{"kind", "t", ...}``)."""
        return [(EVENTS, ns, to_json(msg))]
