"""Bags of every kind a lab records as camera input: Foxglove's image messages (JSON and
protobuf, written with foxglove-sdk), SQLite ``.db3`` bags and rosbag2 folders (written with
rosbags); a bag's end as the session's normal end; and frames that claim more than they hold
(a huge PNG/JPEG header, a channel whose definition is not its type's, bad bytes) refused in
one line before anything is decoded."""

from __future__ import annotations

import base64
import json
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

from perception.bag import BagCamera
from perception.camera import open_camera
from perception.errors import CameraError
from relrl.recording.channels import ROS2_MSGDEFS
from tests.recording.test_bag_camera import scenes

ROOT = Path(__file__).resolve().parents[2]
T0 = 1_700_000_000_000_000_000
#: Foxglove's JSON schemas of its image messages (bytes as base64, as Foxglove defines them).
FOXGLOVE_JSON = {
    "foxglove.CompressedImage": {
        "title": "foxglove.CompressedImage", "type": "object",
        "properties": {"timestamp": {"type": "object"}, "frame_id": {"type": "string"},
                       "data": {"type": "string", "contentEncoding": "base64"},
                       "format": {"type": "string"}}},
    "foxglove.RawImage": {
        "title": "foxglove.RawImage", "type": "object",
        "properties": {"timestamp": {"type": "object"}, "frame_id": {"type": "string"},
                       "width": {"type": "integer"}, "height": {"type": "integer"},
                       "encoding": {"type": "string"}, "step": {"type": "integer"},
                       "data": {"type": "string", "contentEncoding": "base64"}}},
}


def faces(n: int) -> list[np.ndarray]:
    """``n`` frames of the caregiver's face in front of the robot (lighting varying)."""
    from perception.render import SceneView, render

    return [render(SceneView("centre", "frontal", {}, 0.9 + 0.02 * i, i), (320, 240))
            for i in range(n)]


def _png(frame: np.ndarray) -> bytes:
    import cv2

    return cv2.imencode(".png", frame)[1].tobytes()


def huge_png(width: int = 16000, height: int = 16000) -> bytes:
    """A real PNG of ``width x height`` black pixels, 1 bit each: 31 kB, which zstd makes a
    1.4 kB bag; decoded as BGR it is 768 MB."""
    def chunk(kind: bytes, body: bytes) -> bytes:
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))
    row = b"\0" * (1 + (width + 7) // 8)
    deflate = zlib.compressobj(9)
    idat = b"".join(deflate.compress(row) for _ in range(height)) + deflate.flush()
    ihdr = struct.pack(">IIBBBBB", width, height, 1, 0, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat)
            + chunk(b"IEND", b""))


def write_foxglove(path: Path, frames: list, *, encoding: str = "protobuf",
                   kind: str = "compressed", topic: str = "/camera", hz: float = 20.0,
                   messages: list[dict] | None = None) -> Path:
    """An MCAP file written by foxglove-sdk: its own protobuf channels, or JSON channels
    with Foxglove's JSON schemas. ``frames`` are BGR arrays (or PNG bytes, compressed)."""
    import foxglove
    from foxglove.channels import CompressedImageChannel, RawImageChannel
    from foxglove.messages import CompressedImage, RawImage, Timestamp

    name = "foxglove.CompressedImage" if kind == "compressed" else "foxglove.RawImage"
    with foxglove.open_mcap(path, allow_overwrite=True):
        if encoding == "json":
            channel = foxglove.Channel(topic, schema=FOXGLOVE_JSON[name])
        else:
            channel = (CompressedImageChannel if kind == "compressed" else RawImageChannel)(topic)
        items = messages if messages is not None else frames
        for i, frame in enumerate(items):
            ns = T0 + int(i * 1e9 / hz)
            stamp = {"sec": ns // 10**9, "nsec": ns % 10**9}
            if messages is not None:
                msg = frame
            elif kind == "compressed":
                data = frame if isinstance(frame, bytes) else _png(frame)
                msg = {"timestamp": stamp, "frame_id": "camera", "format": "png", "data": data}
            else:
                h, w = frame.shape[:2]
                msg = {"timestamp": stamp, "frame_id": "camera", "width": w, "height": h,
                       "encoding": "bgr8", "step": w * 3, "data": frame.tobytes()}
            if encoding == "json":
                if isinstance(msg.get("data"), bytes):
                    msg = {**msg, "data": base64.b64encode(msg["data"]).decode()}
                channel.log(msg, log_time=ns)
            else:
                fields = {**msg, "timestamp": Timestamp(**msg["timestamp"])}
                channel.log((CompressedImage if kind == "compressed" else RawImage)(**fields),
                            log_time=ns)
    return path


def write_rosbag(folder: Path, frames: list, *, kind: str = "compressed",
                 msgtype: str | None = None, msgdef: str | None = None, hz: float = 20.0,
                 raw_messages: list[bytes] | None = None, compressed: bool = False) -> Path:
    """A SQLite ROS 2 bag written by rosbags (a folder: metadata.yaml and one .db3 file);
    returns the .db3 file. ``frames`` are BGR arrays (or PNG bytes, compressed)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    real = ("sensor_msgs/msg/CompressedImage" if kind == "compressed"
            else "sensor_msgs/msg/Image")
    msgtype = msgtype or real
    writer = Writer(folder, version=9, storage_plugin=StoragePlugin.SQLITE3)
    if compressed:  # each message compressed with zstd (said in metadata.yaml only)
        from rosbags.rosbag2 import CompressionFormat, CompressionMode

        writer.set_compression(CompressionMode.MESSAGE, CompressionFormat.ZSTD)
    with writer:
        if msgdef is not None:  # a definition of the bag's own (perhaps not its type's)
            named = get_typestore(Stores.EMPTY)
            named.register(get_types_from_msg(msgdef, msgtype))
            conn = writer.add_connection("/camera/image", msgtype, typestore=named)
        else:
            conn = writer.add_connection("/camera/image", msgtype, typestore=store)
        Header = store.types["std_msgs/msg/Header"]
        Time = store.types["builtin_interfaces/msg/Time"]
        items = raw_messages if raw_messages is not None else frames
        for i, frame in enumerate(items):
            ns = T0 + int(i * 1e9 / hz)
            if raw_messages is not None:
                writer.write(conn, ns, frame)
                continue
            header = Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id="cam")
            if kind == "compressed":
                data = frame if isinstance(frame, bytes) else _png(frame)
                msg = store.types[real](header=header, format="png",
                                        data=np.frombuffer(data, np.uint8))
            else:
                h, w = frame.shape[:2]
                msg = store.types[real](header=header, height=h, width=w, encoding="bgr8",
                                        is_bigendian=0, step=w * 3,
                                        data=np.frombuffer(frame.tobytes(), np.uint8))
            writer.write(conn, ns, store.serialize_cdr(msg, real))
    return next(folder.glob("*.db3"))


def relrl(*args: str, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "relrl", *args], capture_output=True,
                          text=True, timeout=timeout, cwd=ROOT)


def one_line(out: subprocess.CompletedProcess, says: str, names: str) -> None:
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert says in lines[0] and names in lines[0], lines[0]
    assert "Traceback" not in out.stderr


# ---- every format read back exactly --------------------------------------------------------

@pytest.mark.parametrize("encoding", ["protobuf", "json"])
@pytest.mark.parametrize("kind", ["compressed", "raw"])
def test_foxglove_images_read_back_exactly(tmp_path: Path, encoding: str, kind: str) -> None:
    frames = scenes(4)
    bag = write_foxglove(tmp_path / "fox.mcap", frames, encoding=encoding, kind=kind)
    with BagCamera(bag, paced=False) as cam:
        assert cam.topic == "/camera" and cam.count == 4
        assert cam.type == ("foxglove.CompressedImage" if kind == "compressed"
                            else "foxglove.RawImage")
        got = list(cam)
    assert len(got) == 4
    for a, b in zip(frames, got, strict=True):
        assert np.array_equal(a, b)  # bgr8 and PNG are lossless


@pytest.mark.parametrize("kind", ["compressed", "raw"])
def test_db3_bags_and_rosbag2_folders_read_back_exactly(tmp_path: Path, kind: str) -> None:
    frames = scenes(4)
    db3 = write_rosbag(tmp_path / "bag", frames, kind=kind)
    for source in (str(db3), str(tmp_path / "bag"), f"{db3}:/camera/image",
                   f"{tmp_path / 'bag'}:/camera/image"):
        with open_camera(source) as cam:
            assert isinstance(cam, BagCamera) and cam.count == 4
            cam.paced = False
            got = list(cam)
        assert len(got) == 4
        for a, b in zip(frames, got, strict=True):
            assert np.array_equal(a, b)


def test_a_message_compressed_bag_is_read_through_its_folder(tmp_path: Path) -> None:
    frames = scenes(3)
    db3 = write_rosbag(tmp_path / "bag", frames, kind="raw", compressed=True)
    with BagCamera(tmp_path / "bag", paced=False) as cam:
        got = list(cam)
    assert len(got) == 3 and all(np.array_equal(a, b) for a, b in zip(frames, got, strict=True))
    one_line(relrl("perceive", str(db3)), f"give its folder {tmp_path / 'bag'}",
             db3.name)  # the .db3 alone does not say its messages are compressed


@pytest.mark.slow
def test_db3_paced_at_recorded_times(tmp_path: Path) -> None:
    import time

    db3 = write_rosbag(tmp_path / "bag", scenes(10), hz=10.0)
    with open_camera(str(db3)) as cam:
        t0 = time.monotonic()
        n = sum(1 for _ in cam)
        took = time.monotonic() - t0
    assert n == 10 and 0.85 <= took < 3.0
    assert cam.ended and abs(cam.seconds - 0.9) < 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["fox_protobuf", "fox_json", "db3"])
def test_perceive_prints_each_frames_facts(tmp_path: Path, kind: str) -> None:
    frames = scenes(2)
    bag = (write_rosbag(tmp_path / "bag", frames) if kind == "db3" else
           write_foxglove(tmp_path / "fox.mcap", frames, encoding=kind.split("_")[1]))
    out = relrl("perceive", str(bag))
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("% frame") == 2
    assert "see(face)." in out.stdout


# ---- the targets: hello.toml on each kind of bag; the bag's end is the session's ------------

@pytest.mark.slow
@pytest.mark.parametrize("kind", ["fox_protobuf", "fox_json", "db3"])
def test_hello_runs_on_a_bag_to_its_end(tmp_path: Path, kind: str) -> None:
    """hello.toml asks for 12 time units; the bag holds 6 frames (2.5 s): the session ends
    with the bag, exit 0, its summary complete (not partial), and says where the recording
    ended and that the episode asked for more."""
    frames = faces(6)  # at 2 Hz: a robot faster than the camera waits for each frame (on a
    # loaded machine it skips some: every frame shows the caregiver's face)
    bag = (write_rosbag(tmp_path / "bag", frames, hz=2.0) if kind == "db3" else
           write_foxglove(tmp_path / "fox.mcap", frames, encoding=kind.split("_")[1],
                          hz=2.0))
    out = relrl("run", "examples/episodes/hello.toml", "--camera", str(bag), "--out",
                str(tmp_path / "out"), "--no-plots", "--record")
    assert out.returncode == 0, out.stderr
    ended = [x for x in out.stdout.splitlines() if x.startswith("the recording ended at t = ")]
    assert len(ended) == 1, out.stdout
    assert "the episode asked for 12 time units" in ended[0]
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["partial"] is False and summary["stopped_early"] is False
    assert summary["recording_ended"]["t"] == summary["units"]
    assert 1 <= summary["units"] < 12
    assert (tmp_path / "out" / "hello-policy.pl").is_file()
    trace = (tmp_path / "out" / "trace.jsonl").read_text().splitlines()
    assert len(trace) == summary["steps"] and any("see(face)" in x for x in trace)
    record = json.loads((tmp_path / "out" / ".relrl-run.json").read_text())
    assert record["status"] == "complete"
    from relrl.recording.reader import McapRecording

    recorded = McapRecording(tmp_path / "out" / "session.mcap")  # the session's own, whole
    assert recorded.cut is None and len(recorded.rows) == summary["steps"]
    assert recorded.summary["recording_ended"] == summary["recording_ended"]


@pytest.mark.slow
def test_the_policy_is_evaluated_where_the_recording_ended(tmp_path: Path) -> None:
    """An episode with evaluations every 100 time units on a bag of a few: the policy as
    learned when the bag ended is evaluated (on the simulator), as at an episode's end."""
    from tests.monitor.conftest import episode

    script = episode(tmp_path, steps=200, extra="[evaluation]\nevery = 100\nruns = 2\n"
                                                "steps = 20\n")
    bag = write_foxglove(tmp_path / "fox.mcap", scenes(5), hz=2.0)
    out = relrl("run", str(script), "--camera", str(bag), "--out", str(tmp_path / "out"),
                "--no-plots")
    assert out.returncode == 0, out.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert 1 <= summary["units"] < 5 and summary["partial"] is False
    assert [p["units"] for p in summary["evaluation"]] == [0, summary["units"]]


@pytest.mark.slow
def test_a_bag_longer_than_the_episode_ends_with_the_episode(tmp_path: Path) -> None:
    bag = write_foxglove(tmp_path / "fox.mcap", scenes(40), hz=2.0)
    out = relrl("run", "examples/episodes/hello.toml", "--camera", str(bag), "--out",
                str(tmp_path / "out"), "--no-plots")
    assert out.returncode == 0, out.stderr
    assert "the recording ended" not in out.stdout
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["units"] == 12 and "recording_ended" not in summary


# ---- 34.M: a compressed frame's size is read from its header before it is decoded ---------

@pytest.mark.slow
@pytest.mark.parametrize("kind", ["ros_cdr", "fox_protobuf", "fox_json", "db3"])
def test_a_huge_png_in_a_bag_is_refused_before_decoding(tmp_path: Path, kind: str) -> None:
    """A small bag holding a PNG of 16000x16000 pixels: refused from its header, in one line
    (decoding it first cost 1.5 GB of memory and 10 s)."""
    png = huge_png()
    if kind == "ros_cdr":
        from mcap_ros2.writer import Writer

        bag = tmp_path / "huge.mcap"
        with open(bag, "wb") as fh:
            w = Writer(fh)
            schema = w.register_msgdef("sensor_msgs/msg/CompressedImage",
                                       ROS2_MSGDEFS["sensor_msgs/msg/CompressedImage"])
            w.write_message("/camera", schema, {"header": {"stamp": {"sec": 1, "nanosec": 0},
                            "frame_id": ""}, "format": "png", "data": png}, log_time=T0)
            w.finish()
    elif kind == "db3":
        bag = write_rosbag(tmp_path / "bag", [png])
    else:
        bag = write_foxglove(tmp_path / "huge.mcap", [png], encoding=kind.split("_")[1])
    assert bag.stat().st_size < 100_000  # (a .db3 is SQLite pages)
    with pytest.raises(CameraError, match="16000x16000"), BagCamera(bag, paced=False) as cam:
        cam.read()
    # The child's own peak (VmHWM): ru_maxrss would carry over the test process's peak, which
    # Linux keeps across fork and exec (a full suite's pytest is some 670 MB by now).
    script = ("import sys\nfrom relrl.cli import main\n"
              "try:\n    code = main(['perceive', sys.argv[1]])\n"
              "except SystemExit as e:\n    code = e.code\n"
              "hwm = [ln.split()[1] for ln in open('/proc/self/status')\n"
              "       if ln.startswith('VmHWM')]\n"
              "print(hwm[0], code)\n")
    out = subprocess.run([sys.executable, "-c", script, str(bag)], capture_output=True,
                         text=True, timeout=300, cwd=ROOT)
    peak_kb, code = out.stdout.split()
    assert code == "2", out.stderr
    assert int(peak_kb) < 600_000, f"{int(peak_kb) // 1024} MB"  # the frame is 768 MB
    assert "16000x16000" in out.stderr and "megapixels" in out.stderr


def test_a_png_file_claiming_a_huge_size_is_refused_before_decoding(tmp_path: Path) -> None:
    image = tmp_path / "huge.png"
    image.write_bytes(huge_png())
    one_line(relrl("perceive", str(image)), "16000x16000", "huge.png")


# ---- 34.L and its siblings: what a channel claims and what it holds disagree ---------------

def _ros_bag(path: Path, name: str, msgdef: str, msg: dict) -> Path:
    from mcap_ros2.writer import Writer

    with open(path, "wb") as fh:
        w = Writer(fh)
        schema = w.register_msgdef(name, msgdef)
        w.write_message("/camera/image", schema, msg, log_time=T0)
        w.finish()
    return path


_HEADER = {"stamp": {"sec": 1, "nanosec": 0}, "frame_id": ""}


def _bad_bag(tmp_path: Path, case: str) -> Path:
    frame = scenes(1)[0]
    if case == "image_named_compressed_defined":
        return _ros_bag(tmp_path / "bad.mcap", "sensor_msgs/msg/Image",
                        ROS2_MSGDEFS["sensor_msgs/msg/CompressedImage"],
                        {"header": _HEADER, "format": "png", "data": _png(frame)})
    if case == "db3_image_named_compressed_defined":
        return write_rosbag(tmp_path / "bag", [frame], msgtype="sensor_msgs/msg/Image",
                            msgdef=ROS2_MSGDEFS["sensor_msgs/msg/CompressedImage"],
                            raw_messages=[_cdr_compressed(frame)])
    if case == "zero_size":
        return write_foxglove(tmp_path / "bad.mcap", [], kind="raw", encoding="json", messages=[
            {"width": 0, "height": 0, "encoding": "bgr8", "step": 0, "data": ""}])
    if case == "step_short":
        h, w = frame.shape[:2]
        return write_foxglove(tmp_path / "bad.mcap", [], kind="raw", encoding="json",
                              messages=[{"width": w, "height": h, "encoding": "bgr8",
                                         "step": w, "data": base64.b64encode(
                                             frame.tobytes()).decode()}])
    if case == "format":
        return write_foxglove(tmp_path / "bad.mcap", [], encoding="json", messages=[
            {"format": "tiff", "data": base64.b64encode(_png(frame)).decode()}])
    if case == "not_base64":
        return write_foxglove(tmp_path / "bad.mcap", [], encoding="json", messages=[
            {"format": "png", "data": "%%% not base64 %%%"}])
    if case == "png_said_jpeg_cut":
        return write_foxglove(tmp_path / "bad.mcap", [_png(frame)[:300]], encoding="protobuf")
    if case == "bad_protobuf":
        bag = write_foxglove(tmp_path / "bad.mcap", [_png(frame)], encoding="protobuf")
        return _replace_message(bag, b"\x0a\xff\xff\xff\xff\x0f" + b"\x01" * 40)
    if case == "short_data":
        h, w = frame.shape[:2]
        return write_foxglove(tmp_path / "bad.mcap", [], kind="raw", encoding="json",
                              messages=[{"width": w, "height": h, "encoding": "bgr8",
                                         "step": w * 3, "data": base64.b64encode(
                                             frame.tobytes()[:1000]).decode()}])
    if case == "ros_type_as_json":
        bag = write_foxglove(tmp_path / "bad.mcap", [_png(frame)], encoding="json")
        return _replace_message(bag, None, schema_name="sensor_msgs/msg/CompressedImage")
    if case == "protobuf_schema_not_descriptors":
        bag = write_foxglove(tmp_path / "bad.mcap", [_png(frame)], encoding="protobuf")
        return _replace_message(bag, None, schema_data=b"\xff" * 64)
    if case == "truncated_db3":
        db3 = write_rosbag(tmp_path / "bag", scenes(3))
        db3.write_bytes(db3.read_bytes()[:3000])
        return db3
    raise AssertionError(case)


def _cdr_compressed(frame: np.ndarray) -> bytes:
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    msg = store.types["sensor_msgs/msg/CompressedImage"](
        header=Header(stamp=Time(sec=1, nanosec=0), frame_id=""), format="png",
        data=np.frombuffer(_png(frame), np.uint8))
    return store.serialize_cdr(msg, "sensor_msgs/msg/CompressedImage")


def _replace_message(bag: Path, data: bytes | None, *, schema_name: str | None = None,
                     schema_data: bytes | None = None) -> Path:
    """The same MCAP file with its one message's bytes (or its schema's name or data)
    replaced: rewritten with mcap's own writer, everything else kept."""
    from mcap.reader import make_reader
    from mcap.writer import Writer

    with open(bag, "rb") as fh:
        schema, channel, message = next(make_reader(fh).iter_messages())
    out = bag.with_name("replaced.mcap")
    with open(out, "wb") as fh:
        w = Writer(fh)
        w.start()
        sid = w.register_schema(schema_name or schema.name, schema.encoding,
                                schema.data if schema_data is None else schema_data)
        cid = w.register_channel(channel.topic, channel.message_encoding, sid)
        w.add_message(cid, message.log_time, message.data if data is None else data,
                      message.publish_time)
        w.finish()
    return out


@pytest.mark.slow
@pytest.mark.parametrize("case, says", [
    ("image_named_compressed_defined", "no field 'width'"),
    ("db3_image_named_compressed_defined", "no field 'width'"),
    ("zero_size", "0x0 pixels"),
    ("step_short", "rows of step 320 bytes (a row of it is 960 bytes)"),
    ("short_data", "frame of 1000 bytes (240 rows of step 960 are 230400 bytes)"),
    ("ros_type_as_json", "is encoded as 'json', not cdr"),
    ("protobuf_schema_not_descriptors", "protobuf schema does not define"),
    ("format", "unknown image format 'tiff'"),
    ("not_base64", "not base64"),
    ("png_said_jpeg_cut", "cannot be decoded"),
    ("bad_protobuf", "not a protobuf foxglove.CompressedImage"),
    ("truncated_db3", "bag"),
])
def test_a_bag_that_contradicts_itself_is_one_line(tmp_path: Path, case: str, says: str) -> None:
    """perceive and run --camera: one line naming the bag, exit 2, never a traceback."""
    bag = _bad_bag(tmp_path, case)
    one_line(relrl("perceive", str(bag)), says, bag.name)
    if case in ("image_named_compressed_defined", "bad_protobuf"):
        out = relrl("run", "examples/episodes/hello.toml", "--camera", str(bag), "--out",
                    str(tmp_path / "out"), "--no-plots")
        one_line(out, says, bag.name)


def test_the_bag_reading_figures_run() -> None:
    from bench.bag_reading import bench

    figures = bench(frames=3, rounds=1)
    assert figures["frames"] == 3
    assert all(figures[k] > 0 for k in ("mcap_ros2", "rosbags_mcap", "bag_camera_mcap",
                                        "bag_camera_db3"))


def test_a_jpeg_frame_claiming_a_huge_size_is_refused_from_its_header(tmp_path: Path) -> None:
    """The JPEG's frame header (SOF) read from the message's bytes: a real 320x240 JPEG reads
    as such; the same with its SOF saying 16000x16000 is refused before decoding."""
    import cv2

    from perception.imagesize import header_size_of

    jpeg = bytearray(cv2.imencode(".jpg", scenes(1)[0])[1].tobytes())
    assert header_size_of(bytes(jpeg), "a frame") == (320, 240, "JPEG")
    sof = jpeg.index(b"\xff\xc0")
    jpeg[sof + 5:sof + 9] = struct.pack(">HH", 16000, 16000)  # height, width
    bag = write_foxglove(tmp_path / "huge.mcap", [], messages=[
        {"timestamp": {"sec": 1, "nsec": 0}, "frame_id": "", "format": "jpeg",
         "data": bytes(jpeg)}])
    with pytest.raises(CameraError, match="16000x16000"), BagCamera(bag, paced=False) as cam:
        cam.read()


@pytest.mark.parametrize("source, says", [
    ("bag:///dev/zero", "not a regular file"),
    ("bag://{tmp}", "a folder without a metadata.yaml"),
    ("{tmp}/none.db3", "no such bag file"),
])
def test_what_is_not_a_bag_is_named(tmp_path: Path, source: str, says: str) -> None:
    with pytest.raises(CameraError, match=says):
        open_camera(source.format(tmp=tmp_path))
