"""The head in Foxglove's 3D view: a recorded session's ``/tf`` (FrameTransforms), its
``/head/scene`` (the gaze and the caregiver's face) and ``/robot_description`` read back by
independent readers (the ``mcap`` library, protobuf's own library and mcap-ros2-support),
checked against foxglove-sdk's schemas and against the joint states of the same time units;
the shipped URDF against the calibration; the shipped layout against the recording's
topics."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from head import load_calibration
from head.errors import CalibrationError
from head.urdf import DEFAULT_URDF, load_urdf, quaternion
from relrl.cli import main
from relrl.monitor.view import NOMINAL_DEG_PER_US
from relrl.recording.channels import CHANNELS, SCENE
from relrl.recording.layout import LAYOUT, layout_json, topics_of
from relrl.recording.scene import face_position
from tests.monitor.conftest import episode
from tests.recording.foxglove_proto import protobuf_decoder

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def messages(tmp_path_factory) -> dict[str, list]:
    """A 30-unit session on the simulated head, every frame recorded: topic -> [(log
    time, decoded message, schema)]."""
    tmp = tmp_path_factory.mktemp("rec3d")
    out = tmp / "session"
    assert main(["run", str(episode(tmp, steps=30)), "--out", str(out), "--head", "sim",
                 "--record", "--record-rate", "0", "--no-plots"]) == 0
    got: dict[str, list] = {}
    with open(out / "session.mcap", "rb") as fh:
        for schema, channel, message in make_reader(fh).iter_messages():
            if channel.message_encoding == "protobuf":
                msg = protobuf_decoder(schema)(message.data)
            elif channel.message_encoding == "cdr":
                msg = DecoderFactory().decoder_for("cdr", schema)(message.data)
            else:
                msg = json.loads(message.data)
            got.setdefault(channel.topic, []).append((message.log_time, msg, schema))
    return got


@pytest.mark.slow
def test_the_schemas_are_foxglove_sdks(messages) -> None:
    from foxglove.messages import FrameTransforms, ImageAnnotations, SceneUpdate

    for topic, cls in (("/tf", FrameTransforms), ("/head/scene", SceneUpdate),
                       ("/camera/annotations", ImageAnnotations)):
        schema = messages[topic][0][2]
        sdk = cls.get_schema()
        assert (schema.name, schema.encoding) == (sdk.name, sdk.encoding) == \
            (f"foxglove.{cls.__name__}", "protobuf")
        assert bytes(schema.data) == bytes(sdk.data)


def _angle_about(q, axis) -> float:
    """The angle of the rotation ``q`` (protobuf Quaternion) about ``axis``; the rotation
    must be about that axis."""
    v = (q.x, q.y, q.z)
    s = math.sqrt(sum(c * c for c in v))
    if s < 1e-12:
        return 0.0
    dot = sum(a * b for a, b in zip(v, axis, strict=True)) / s
    assert abs(abs(dot) - 1) < 1e-9, "a rotation about another axis"
    return math.copysign(2 * math.atan2(s, q.w), dot)


def test_transforms_match_the_joint_states_at_the_same_times(messages) -> None:
    kinematics = load_urdf()
    joints = {j.child: j for j in kinematics.joints}
    states = {ns: dict(zip(m.name, m.position, strict=True))
              for ns, m, _ in messages["/head/joint_states"]}
    tfs = messages["/tf"]
    assert len(tfs) == len(states) == 30  # one per time unit, on the unit's log time
    assert [ns for ns, _, _ in tfs] == sorted(states)
    turned = 0
    for ns, msg, _ in tfs:
        assert len(msg.transforms) == len(kinematics.joints)
        for tf in msg.transforms:
            joint = joints[tf.child_frame_id]
            assert tf.parent_frame_id == joint.parent
            assert tf.timestamp.seconds * 10**9 + tf.timestamp.nanos == ns
            assert (tf.translation.x, tf.translation.y, tf.translation.z) == joint.xyz
            if joint.kind == "fixed":
                assert (tf.rotation.x, tf.rotation.y, tf.rotation.z, tf.rotation.w) == \
                    (0, 0, 0, 1)
                continue
            position = states[ns][joint.name]
            assert _angle_about(tf.rotation, joint.axis) == pytest.approx(position, abs=1e-9)
            turned += position != 0
    assert turned  # the head moved during the session


def test_the_scene_has_the_gaze_and_the_caregivers_face(messages) -> None:
    scenes = messages["/head/scene"]
    assert len(scenes) == 30
    faces = 0
    for _, msg, _ in scenes:
        by_id = {e.id: e for e in msg.entities}
        gaze = by_id["gaze"]
        assert gaze.frame_id == "camera" and gaze.frame_locked and len(gaze.arrows) == 1
        if "caregiver_face" in by_id:
            face = by_id["caregiver_face"]
            assert face.frame_id == "camera" and face.spheres[0].pose.position.x > 0.2
            assert face.texts[0].text.startswith("caregiver: face ")
            faces += 1
        else:
            assert [d.id for d in msg.deletions] == ["caregiver_face"]
    assert faces  # the rendered caregiver's face was seen


def test_the_robot_description_is_the_shipped_urdf(messages) -> None:
    [(_, msg, schema)] = messages["/robot_description"]
    assert schema.name == "std_msgs/msg/String"
    assert msg.data == DEFAULT_URDF.read_text()


@pytest.mark.parametrize("overlay, expected", [
    (None, None), ({"width": 320, "height": 240, "face": None}, None),
    # a face in the middle of the frame is straight ahead; on the image's left it is on the
    # head's left (+y); higher up it is above (+z); a smaller one is further
    ({"width": 320, "height": 240, "face": {"box": [140, 100, 40, 40]}}, (0.0, 0.0)),
])
def test_a_face_position(overlay, expected) -> None:
    got = face_position(overlay)
    if expected is None:
        assert got is None
    else:
        assert got is not None and got[0] > 0 and got[1:] == pytest.approx(expected)
    frame = {"width": 320, "height": 240}
    left = face_position({**frame, "face": {"box": [10, 100, 40, 40]}})
    up = face_position({**frame, "face": {"box": [140, 10, 40, 40]}})
    far = face_position({**frame, "face": {"box": [150, 110, 20, 20]}})
    assert left[1] > 0 and up[2] > 0 and far[0] == pytest.approx(2 * left[0])


def test_the_urdf_agrees_with_the_calibration() -> None:
    cal = load_calibration()
    kin = load_urdf()
    assert set(kin.moving) <= set(cal.servos)  # the joints are servos (the mouth is none)
    assert {"neck_pan", "neck_tilt", "eye_pan", "eye_tilt"} <= set(kin.moving)
    for joint in kin.joints:
        if joint.kind != "revolute":
            continue
        servo = cal.servos[joint.name]
        per_us = math.radians(NOMINAL_DEG_PER_US)
        assert joint.lower == pytest.approx((servo.min - servo.centre) * per_us, abs=1e-4)
        assert joint.upper == pytest.approx((servo.max - servo.centre) * per_us, abs=1e-4)
    assert kin.root == "base_link"
    assert "camera" in {j.child for j in kin.joints}  # the images' frame


def test_a_joint_turns_about_its_axis_and_stays_in_its_limits() -> None:
    kin = load_urdf()
    by_name = {j.name: (j, q) for j, _, q in kin.transforms({"neck_pan": 0.3,
                                                            "eye_tilt": 5.0})}
    assert by_name["neck_pan"][1] == pytest.approx(quaternion((0, 0, 1), 0.3))
    eye = by_name["eye_tilt"][0]
    assert by_name["eye_tilt"][1] == pytest.approx(quaternion(eye.axis, eye.upper))


@pytest.mark.parametrize("text, needle", [
    ("not xml <", "not XML"),
    ("<robot/>", "no joint"),
    ("<html/>", "not a URDF"),
    ('<robot><joint name="j" type="prismatic"><parent link="a"/><child link="b"/></joint>'
     "</robot>", "'prismatic'"),
    ('<robot><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
     '<axis xyz="0 0"/></joint></robot>', "three numbers"),
    ('<robot><joint name="j" type="revolute"><parent link="a"/></joint></robot>',
     "a parent and a child"),
    ('<robot><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
     '<limit lower="nan" upper="1"/></joint></robot>', "limit lower"),
])
def test_a_bad_urdf_is_one_line_naming_it(tmp_path, text: str, needle: str) -> None:
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(CalibrationError, match="bad.urdf") as err:
        load_urdf(path)
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_the_layout_shows_the_recordings_topics() -> None:
    shipped = json.loads(LAYOUT.read_text())
    assert shipped == json.loads(layout_json())  # the shipped file is the generated one
    topics = topics_of(shipped)
    recorded = {ch.topic for ch in CHANNELS}
    assert topics and topics <= recorded, topics - recorded
    # the panels the dashboard promises: 3D (the scene, the head's description moved by the
    # transforms, which the panel reads from every topic), the image with its annotations,
    # the plots, the tree
    assert '"controlMode": "transforms"' in LAYOUT.read_text()
    assert {SCENE.topic, "/robot_description", "/camera/image/compressed",
            "/camera/annotations", "/relrl/necessities", "/relrl/interaction",
            "/relrl/tree"} <= topics
    kinds = [p["panelType"] for p in _panels(shipped["content"])]
    assert {"ThreeDee", "Image", "Plot", "RawMessages"} <= set(kinds)


def _panels(content: dict) -> list[dict]:
    if content.get("type") == "panel":
        return [content]
    return [p for item in content.get("items", []) for p in _panels(item["content"])]
