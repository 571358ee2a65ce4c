"""How fast bags are read: the figures behind reading MCAP with the ``mcap`` library and
``.db3`` with ``rosbags`` (docs/recording.md, "A robot's bag as the camera").

One bag of ``frames`` raw ``rgb8`` frames of 640x480 (random pixels), written once as MCAP by
``mcap-ros2-support`` and once as a SQLite ``.db3`` by ``rosbags``, in a temporary folder.
Timed, best of ``rounds``, in seconds for all frames:

* ``mcap_ros2``: the MCAP file read with ``mcap`` (CRCs checked) and decoded by
  ``mcap-ros2-support`` -- what :class:`perception.bag.BagCamera` does for MCAP;
* ``rosbags_mcap``: the same file read and decoded by ``rosbags`` -- the alternative;
* ``bag_camera_mcap``, ``bag_camera_db3``: every frame as BGR through
  :class:`~perception.bag.BagCamera` (``paced=False``), for both containers.

Run ``python -m bench.bag_reading [FRAMES]`` from the checkout (needs the ``mcap`` extra);
prints JSON.
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

__all__ = ["bench"]

_IMAGE_MSG = """std_msgs/Header header
uint32 height
uint32 width
string encoding
uint8 is_bigendian
uint32 step
uint8[] data
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
"""


def _write(folder: Path, frames: int) -> tuple[Path, Path]:
    from mcap_ros2.writer import Writer as McapWriter
    from rosbags.rosbag2 import StoragePlugin
    from rosbags.rosbag2 import Writer as BagWriter
    from rosbags.typesys import Stores, get_typestore

    pixels = np.random.default_rng(0).integers(0, 256, (480, 640, 3), np.uint8).tobytes()
    mcap = folder / "frames.mcap"
    with open(mcap, "wb") as fh:
        writer = McapWriter(fh)
        schema = writer.register_msgdef("sensor_msgs/msg/Image", _IMAGE_MSG)
        for i in range(frames):
            writer.write_message("/camera", schema, {
                "header": {"stamp": {"sec": i, "nanosec": 0}, "frame_id": "camera"},
                "height": 480, "width": 640, "encoding": "rgb8", "is_bigendian": 0,
                "step": 1920, "data": pixels}, log_time=i * 10**8, publish_time=i * 10**8)
        writer.finish()
    store = get_typestore(Stores.ROS2_HUMBLE)
    image = store.types["sensor_msgs/msg/Image"]
    header = store.types["std_msgs/msg/Header"]
    stamp = store.types["builtin_interfaces/msg/Time"]
    with BagWriter(folder / "db3", version=9, storage_plugin=StoragePlugin.SQLITE3) as bag:
        conn = bag.add_connection("/camera", "sensor_msgs/msg/Image", typestore=store)
        for i in range(frames):
            msg = image(header=header(stamp=stamp(sec=i, nanosec=0), frame_id="camera"),
                        height=480, width=640, encoding="rgb8", is_bigendian=0, step=1920,
                        data=np.frombuffer(pixels, np.uint8))
            bag.write(conn, i * 10**8, store.serialize_cdr(msg, "sensor_msgs/msg/Image"))
    return mcap, next((folder / "db3").glob("*.db3"))


def _mcap_ros2(path: Path) -> int:
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    with open(path, "rb") as fh:
        reader = make_reader(fh, validate_crcs=True, decoder_factories=[DecoderFactory()])
        return sum(len(bytes(m.data)) for *_, m in reader.iter_decoded_messages())


def _rosbags(path: Path) -> int:
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    with Reader(path) as reader:
        store = get_typestore(Stores.EMPTY)
        for c in reader.connections:
            store.register(get_types_from_msg(c.msgdef.data, c.msgtype))
        return sum(len(bytes(store.deserialize_cdr(raw, c.msgtype).data))
                   for c, _, raw in reader.messages())


def _camera(path: Path) -> int:
    from perception.bag import BagCamera

    with BagCamera(path, paced=False) as cam:
        return sum(frame.size for frame in cam)


def _best(fn: Callable[[Path], int], path: Path, rounds: int) -> float:
    times = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        fn(path)
        times.append(time.perf_counter() - t0)
    return round(min(times), 3)


def bench(frames: int = 200, rounds: int = 3) -> dict[str, float | int]:
    """The figures (seconds for all ``frames``, best of ``rounds``)."""
    with tempfile.TemporaryDirectory() as tmp:
        mcap, db3 = _write(Path(tmp), frames)
        return {"frames": frames, "mcap_ros2": _best(_mcap_ros2, mcap, rounds),
                "rosbags_mcap": _best(_rosbags, mcap, rounds),
                "bag_camera_mcap": _best(_camera, mcap, rounds),
                "bag_camera_db3": _best(_camera, db3, rounds)}


if __name__ == "__main__":
    print(json.dumps(bench(int(sys.argv[1]) if len(sys.argv) > 1 else 200)))
