"""The head in 3D: its frames, where it looks and where the caregiver's face is, in Foxglove's
own messages built with foxglove-sdk's schemas (protobuf).

* ``/tf`` -- a ``foxglove.FrameTransforms`` per time unit: every joint of the head's robot
  description (:mod:`head.urdf`, ``wha8030.urdf`` by default), parent link to child link, the
  moving joints turned by the same positions as that unit's ``/head/joint_states``
  (:func:`~relrl.recording.channels.joint_state_of`).
* ``/head/scene`` -- a ``foxglove.SceneUpdate`` per time unit: the gaze, an arrow along the
  camera's x axis, and the caregiver's face, a sphere with its pose written beside it, placed
  in the camera's frame from the face box perception found (:func:`face_position`); without a
  face in the frame the face entity is deleted.
* ``/robot_description`` -- the URDF's text once, at the start, as ROS 2's
  ``std_msgs/msg/String`` (what Foxglove's 3D panel and ROS tools read a description from).

The face's distance is a pinhole estimate: a face :data:`FACE_WIDTH_M` wide seen through a
camera of :data:`HORIZONTAL_FOV_DEG`; it places the face in front of the head, it does not
measure it.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["FACE_WIDTH_M", "HORIZONTAL_FOV_DEG", "SceneEncoder", "encode_annotations",
           "face_position"]

#: the width of a face, metres (for the distance of the caregiver's face).
FACE_WIDTH_M = 0.15
#: the camera's horizontal field of view, degrees (a common webcam's).
HORIZONTAL_FOV_DEG = 60.0
#: the gaze arrow's length, metres.
GAZE_LENGTH_M = 0.6
#: the frame of the camera images and of the scene's primitives.
CAMERA_FRAME = "camera"


def face_position(overlay: dict[str, Any] | None) -> tuple[float, float, float] | None:
    """Where the caregiver's face is in the camera's frame (x forward, y left, z up, metres),
    from the face box in ``overlay`` (``face.box`` and the frame's ``width`` and
    ``height``), or ``None`` without a face."""
    face = (overlay or {}).get("face")
    width, height = (overlay or {}).get("width"), (overlay or {}).get("height")
    if not face or not width or not height:
        return None
    x, y, w, h = (float(v) for v in face["box"])
    focal = (width / 2) / math.tan(math.radians(HORIZONTAL_FOV_DEG) / 2)
    depth = FACE_WIDTH_M * focal / max(w, 1.0)
    u, v = x + w / 2 - width / 2, y + h / 2 - height / 2  # right and down of the centre
    return (depth, -u * depth / focal, -v * depth / focal)


def _stamp(ns: int) -> Any:
    from foxglove.messages import Timestamp

    return Timestamp(ns // 1_000_000_000, ns % 1_000_000_000)


class SceneEncoder:
    """Encode the head's transforms and scene with foxglove-sdk's message classes.

    Args:
        urdf: the head's robot description (default: the shipped WHA-8030's).

    Raises:
        CalibrationError: the description cannot be read.
    """

    def __init__(self, urdf: str | None = None) -> None:
        from head.urdf import DEFAULT_URDF, load_urdf

        path = urdf or DEFAULT_URDF
        self.kinematics = load_urdf(path)
        self.description = open(path, encoding="utf-8").read()  # noqa: SIM115 - read whole

    def transforms(self, ns: int, positions: dict[str, float]) -> bytes:
        """A ``foxglove.FrameTransforms`` of every joint at ``positions`` (radians)."""
        from foxglove.messages import FrameTransform, FrameTransforms, Quaternion, Vector3

        stamp = _stamp(ns)
        return FrameTransforms(transforms=[
            FrameTransform(timestamp=stamp, parent_frame_id=joint.parent,
                           child_frame_id=joint.child,
                           translation=Vector3(x=xyz[0], y=xyz[1], z=xyz[2]),
                           rotation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]))
            for joint, xyz, q in self.kinematics.transforms(positions)]).encode()

    def scene(self, ns: int, overlay: dict[str, Any] | None) -> bytes:
        """A ``foxglove.SceneUpdate``: the gaze arrow, and the caregiver's face when seen."""
        from foxglove.messages import (
            ArrowPrimitive,
            Color,
            Pose,
            Quaternion,
            SceneEntity,
            SceneEntityDeletion,
            SceneUpdate,
            SpherePrimitive,
            TextPrimitive,
            Vector3,
        )

        stamp = _stamp(ns)
        level = Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)
        entities = [SceneEntity(
            timestamp=stamp, frame_id=CAMERA_FRAME, id="gaze", frame_locked=True,
            arrows=[ArrowPrimitive(
                pose=Pose(position=Vector3(x=0.0, y=0.0, z=0.0), orientation=level),
                shaft_length=GAZE_LENGTH_M - 0.05, shaft_diameter=0.008, head_length=0.05,
                head_diameter=0.025, color=Color(r=1.0, g=0.55, b=0.0, a=0.9))])]
        deletions = []
        where = face_position(overlay)
        if where is None:
            deletions.append(SceneEntityDeletion(timestamp=stamp, id="caregiver_face"))
        else:
            face = (overlay or {})["face"]
            at = Vector3(x=where[0], y=where[1], z=where[2])
            above = Vector3(x=where[0], y=where[1], z=where[2] + 0.12)
            entities.append(SceneEntity(
                timestamp=stamp, frame_id=CAMERA_FRAME, id="caregiver_face",
                spheres=[SpherePrimitive(pose=Pose(position=at, orientation=level),
                                         size=Vector3(x=FACE_WIDTH_M, y=FACE_WIDTH_M,
                                                      z=FACE_WIDTH_M * 1.3),
                                         color=Color(r=0.2, g=0.9, b=0.3, a=0.6))],
                texts=[TextPrimitive(pose=Pose(position=above, orientation=level),
                                     billboard=True, font_size=14.0, scale_invariant=True,
                                     color=Color(r=0.2, g=0.9, b=0.3, a=1.0),
                                     text=f"caregiver: face {face.get('pose')}")]))
        return SceneUpdate(deletions=deletions, entities=entities).encode()


def encode_annotations(msg: dict[str, Any]) -> bytes:
    """A :func:`~relrl.recording.channels.annotations_of` message (the face box and label,
    the salient area's box, cross and label) as foxglove-sdk's ``foxglove.ImageAnnotations``.
    """
    from foxglove.messages import (
        Color,
        ImageAnnotations,
        Point2,
        PointsAnnotation,
        PointsAnnotationType,
        TextAnnotation,
        Timestamp,
    )

    def color(c: dict[str, float]) -> Any:
        return Color(r=c["r"], g=c["g"], b=c["b"], a=c["a"])

    def stamp(s: dict[str, int]) -> Any:
        return Timestamp(s["sec"], s["nsec"])

    kinds = (PointsAnnotationType.Unknown, PointsAnnotationType.Points,
             PointsAnnotationType.LineLoop, PointsAnnotationType.LineStrip,
             PointsAnnotationType.LineList)  # by the message's number
    points = [PointsAnnotation(
        timestamp=stamp(p["timestamp"]), type=kinds[p["type"]],
        points=[Point2(x=q["x"], y=q["y"]) for q in p["points"]],
        outline_color=color(p["outline_color"]), fill_color=color(p["fill_color"]),
        outline_colors=[color(c) for c in p["outline_colors"]], thickness=p["thickness"])
        for p in msg["points"]]
    texts = [TextAnnotation(
        timestamp=stamp(t["timestamp"]), position=Point2(x=t["position"]["x"],
                                                         y=t["position"]["y"]),
        text=t["text"], font_size=t["font_size"], text_color=color(t["text_color"]),
        background_color=color(t["background_color"])) for t in msg["texts"]]
    return ImageAnnotations(points=points, texts=texts).encode()
