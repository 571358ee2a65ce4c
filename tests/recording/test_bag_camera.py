"""A robot's ROS 2 bag as camera input, the bag written by mcap-ros2-support (an independent
writer) from synthetic frames; and every way a bag can be wrong is one line, exit 2."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from perception.bag import BagCamera
from perception.camera import open_camera
from perception.errors import CameraError
from perception.render import SceneView, render
from relrl.recording.channels import ROS2_MSGDEFS

pytestmark = pytest.mark.slow  # every test here takes a second or more

ROOT = Path(__file__).resolve().parents[2]


def scenes(n: int) -> list[np.ndarray]:
    looks = ["left", "centre", "right", "left_down", "right_down"]
    return [render(SceneView(looks[i % len(looks)], "frontal",
                             {"left_down": "apple", "right": "lemon"}, 1.0, i), (320, 240))
            for i in range(n)]


def write_bag(path: Path, frames: list[np.ndarray], *, kind: str = "raw",
              topic: str = "/camera/image_raw", hz: float = 20.0, encoding: str = "rgb8",
              extra_topic: bool = False) -> Path:
    """A ROS 2 bag written with mcap-ros2-support's writer, as rosbag2 would."""
    import cv2
    from mcap_ros2.writer import Writer

    with open(path, "wb") as fh:
        writer = Writer(fh)
        if extra_topic:
            js = writer.register_msgdef("sensor_msgs/msg/JointState",
                                        ROS2_MSGDEFS["sensor_msgs/msg/JointState"])
        name = "sensor_msgs/msg/CompressedImage" if kind == "compressed" else \
            "sensor_msgs/msg/Image"
        schema = writer.register_msgdef(name, ROS2_MSGDEFS[name])
        t0 = 1_700_000_000_000_000_000
        for i, frame in enumerate(frames):
            ns = t0 + int(i * 1e9 / hz)
            header = {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9},
                      "frame_id": "camera"}
            if kind == "compressed":
                ok, data = cv2.imencode(".png", frame)
                msg = {"header": header, "format": "png", "data": data.tobytes()}
            else:
                h, w = frame.shape[:2]
                img = cv2.cvtColor(frame, cv2.COLOR_BGR2RGB) if encoding == "rgb8" else frame
                msg = {"header": header, "height": h, "width": w, "encoding": encoding,
                       "is_bigendian": 0, "step": w * 3, "data": img.tobytes()}
            writer.write_message(topic, schema, msg, log_time=ns, publish_time=ns)
            if extra_topic:
                writer.write_message("/joint_states", js, {
                    "header": header, "name": ["pan"], "position": [0.1], "velocity": [],
                    "effort": []}, log_time=ns, publish_time=ns)
        writer.finish()
    return path


@pytest.mark.parametrize("kind", ["raw", "compressed"])
def test_bag_frames_read_back_exactly(tmp_path: Path, kind: str) -> None:
    frames = scenes(6)
    bag = write_bag(tmp_path / "robot.mcap", frames, kind=kind, extra_topic=True)
    with BagCamera(bag, paced=False) as cam:
        assert cam.topic == "/camera/image_raw" and cam.count == 6
        got = list(cam)
    assert len(got) == 6
    for a, b in zip(frames, got, strict=True):
        assert np.array_equal(a, b)  # rgb8 and PNG are lossless


def test_bag_at_recorded_times(tmp_path: Path) -> None:
    """Paced: a robot faster than the camera waits for each frame (20 frames at 20 Hz take
    about a second); a slower one skips what it missed."""
    bag = write_bag(tmp_path / "robot.mcap", scenes(20), hz=20.0)
    with open_camera(str(bag)) as cam:
        t0 = time.monotonic()
        n = sum(1 for _ in cam)
        took = time.monotonic() - t0
    assert n == 20 and 0.9 <= took < 3.0
    with open_camera(f"{bag}:/camera/image_raw") as cam:
        cam.read()
        time.sleep(0.5)  # ten frames' time
        cam.read()
        assert cam.skipped >= 8


def test_perceive_bag_prints_facts_per_frame(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / "robot.mcap", scenes(3), kind="compressed")
    out = subprocess.run([sys.executable, "-m", "relrl", "perceive", str(bag)],
                         capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("% frame") == 3
    assert "see(face)." in out.stdout


def test_session_runs_on_a_bag(tmp_path: Path) -> None:
    """relrl run --camera BAG.mcap perceives the bag's frames (the session ends when the
    bag does, keeping what it learned)."""
    from tests.monitor.conftest import episode

    # 20 s of camera for a 20-step session: time to spare on a loaded machine (frames are
    # played at their recorded times, so a slow step skips frames)
    bag = write_bag(tmp_path / "robot.mcap", scenes(100), hz=5.0)
    script = episode(tmp_path, steps=20)
    out = subprocess.run([sys.executable, "-m", "relrl", "run", str(script), "--camera",
                          f"{bag}:/camera/image_raw", "--out", str(tmp_path / "out"),
                          "--no-plots"], capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    trace = (tmp_path / "out" / "trace.jsonl").read_text().splitlines()
    assert len(trace) == 20
    assert any("see(face)" in line for line in trace)


def _cut(path: Path) -> Path:
    data = path.read_bytes()
    cut = path.with_name("cut.mcap")
    cut.write_bytes(data[:len(data) * 2 // 3])
    return cut


@pytest.mark.parametrize("case, says", [
    ("no_image", "no image topic"),
    ("encoding", "unknown image encoding '32FC1'"),
    ("cut", "cut short"),
    ("not_mcap", "not an MCAP file"),
    ("topic", "no topic '/nope'"),
    ("damaged", "damaged MCAP file"),
])
def test_bad_bags_are_one_line(tmp_path: Path, case: str, says: str) -> None:
    from mcap_ros2.writer import Writer

    bag = tmp_path / "bad.mcap"
    source = str(bag)
    if case == "no_image":
        with open(bag, "wb") as fh:
            w = Writer(fh)
            js = w.register_msgdef("sensor_msgs/msg/JointState",
                                   ROS2_MSGDEFS["sensor_msgs/msg/JointState"])
            w.write_message("/joint_states", js, {"header": {"stamp": {"sec": 1, "nanosec": 0},
                            "frame_id": ""}, "name": [], "position": [], "velocity": [],
                            "effort": []}, log_time=1)
            w.finish()
    elif case == "encoding":
        write_bag(bag, scenes(2), encoding="32FC1")
    elif case == "cut":
        source = str(_cut(write_bag(bag, scenes(8), kind="compressed")))
    elif case == "not_mcap":
        bag.write_bytes(b"#ROSBAG V2.0\n" + b"\0" * 100)
    elif case == "topic":
        source = f"{write_bag(bag, scenes(2))}:/nope"
    elif case == "damaged":
        from mcap.reader import make_reader

        write_bag(bag, scenes(4))
        with open(bag, "rb") as fh:
            chunk = make_reader(fh).get_summary().chunk_indexes[0]
        data = bytearray(bag.read_bytes())
        for i in range(chunk.chunk_start_offset + 300, chunk.chunk_start_offset + 364):
            data[i] ^= 0xFF
        bag.write_bytes(bytes(data))
    if case in ("encoding", "damaged"):
        with pytest.raises(CameraError, match=says), open_camera(source) as cam:
            cam.read()
    else:
        with pytest.raises(CameraError, match=says):
            open_camera(source)
    out = subprocess.run([sys.executable, "-m", "relrl", "perceive", source],
                         capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and says in lines[0] and Path(source.split(".mcap:")[0]).name in lines[0]
    assert "Traceback" not in out.stderr
