"""Recording frames and the extended trace; perceiving the recorded frames again."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from perception import Perceiver, open_camera
from perception.errors import CameraError
from perception.render import SceneView, render
from relrl.cli import main
from relrl.monitor.frames import decode_jpeg
from relrl.recording.reader import McapRecording
from tests.monitor.conftest import episode


def test_frames_round_trip_through_jpeg(tmp_path: Path) -> None:
    """A frame as the session records it: JPEG in a ROS 2 CompressedImage, decoded by
    mcap-ros2-support, close to the frame."""
    from mcap.records import Schema
    from mcap_ros2.decoder import DecoderFactory

    from relrl.monitor.frames import encode_jpeg
    from relrl.recording.channels import IMAGE
    from relrl.recording.encoder import Encoder

    frames = [render(SceneView(place, "frontal", {"left": "apple"}, 1.0, k))
              for k, place in enumerate(["centre", "left", "down", "right"])]
    encoder = Encoder()
    schema = Schema(id=1, name=IMAGE.schema, encoding="ros2msg", data=IMAGE.schema_data)
    decode = DecoderFactory().decoder_for("cdr", schema)
    for t, frame in enumerate(frames, 1):
        jpeg = encode_jpeg(frame, 90)
        messages = encoder.unit(t, {"t": t, "percepts": [], "overlay": None, "frame": t}, jpeg)
        image = [decode(data) for ch, _, data in messages if ch is IMAGE]
        assert len(image) == 1 and image[0].format == "jpeg" and bytes(image[0].data) == jpeg
        back = decode_jpeg(bytes(image[0].data))
        assert back.shape == frame.shape
        err = np.abs(back.astype(int) - frame.astype(int)).mean()
        psnr = 10 * np.log10(255 ** 2 / np.mean((back.astype(float) - frame) ** 2))
        assert err < 3 and psnr > 30, (err, psnr)


@pytest.mark.slow
def test_the_rate_limits_recorded_frames(tmp_path: Path) -> None:
    """--record-rate 1 on a session far shorter than a second: one frame."""
    script = episode(tmp_path, steps=30)
    out = tmp_path / "rec"
    assert main(["run", str(script), "--out", str(out), "--record", "--record-rate", "1",
                 "--no-plots"]) == 0
    rec = McapRecording(out / "session.mcap")
    assert len(rec.rows) == 30
    assert 1 <= len(rec.frames) <= 1 + 30 * 0.5  # a unit takes longer than 2 ms
    assert sum(1 for r in rec.rows if r.get("frame")) == len(rec.frames)


@pytest.mark.slow
def test_recorded_frames_are_perceived_again(tmp_path: Path) -> None:
    script = episode(tmp_path, steps=40)
    out = tmp_path / "rec"
    assert main(["run", str(script), "--out", str(out), "--record", "--record-rate", "0",
                 "--record-quality", "95", "--no-plots"]) == 0
    rows = [json.loads(x) for x in (out / "trace.jsonl").read_text().splitlines()]
    rec = McapRecording(out / "session.mcap")
    assert rec.rows == rows  # the recording holds the trace, every field
    assert len(rec.frames) == 41 and [r["frame"] for r in rows] == list(range(1, 41))
    for key in ("percepts", "memory", "memory_size", "activation", "necessity", "reward",
                "response", "explanation", "head", "metrics", "overlay"):
        assert key in rows[0], key
    assert all(isinstance(a, int) and isinstance(e, str) for a, e in rows[5]["memory"])
    # perception run again on the recorded frames gives the facts the robot decided on
    perceiver = Perceiver()
    camera = open_camera(f"recording://{out}")
    same = 0
    for row in rows:
        facts = perceiver.perceive(camera.read(), looking_at=row["frame_looking_at"])
        from relrl.terms import format_term

        seen = [format_term(f) for f in facts if f[0] not in ("pan", "tilt")] \
            or ["see(environment)"]
        recorded = [p for p in row["percepts"] if not p.startswith(("hear(", "at("))
                    or p.startswith("at(object")]
        same += seen == recorded
    assert same >= 39, f"only {same} of 40 frames perceived as recorded"
    # and a whole session runs on them as its camera
    again = tmp_path / "again"
    assert main(["run", str(script), "--camera", str(out), "--out", str(again),
                 "--no-plots"]) == 0
    rows2 = [json.loads(x) for x in (again / "trace.jsonl").read_text().splitlines()]
    assert len(rows2) == 40 and any("see(face)" in r["percepts"] for r in rows2)


def test_not_a_recording_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(CameraError, match="not a recorded session"):
        open_camera(f"recording://{tmp_path}")
    assert main(["replay", str(tmp_path)]) == 2


@pytest.mark.slow
def test_device_runs_label_simulated_evaluations(tmp_path: Path, capsys) -> None:
    script = episode(tmp_path, steps=20, extra="[evaluation]\nevery = 10\nruns = 1\n"
                                               "steps = 10\n")
    out = tmp_path / "dev"
    assert main(["run", str(script), "--camera", "synthetic://?pose=frontal", "--out",
                 str(out), "--no-plots"]) == 0
    console = capsys.readouterr()
    assert "evaluation (simulated) after" in console.out
    assert "SIMULATED" in console.err  # the log line of each evaluation
    summary = json.loads((out / "summary.json").read_text())
    assert summary["where"]["simulated_evaluation"] is True
    assert summary["where"]["learning"].startswith("devices (camera synthetic://")
    assert all(p["on"] == "simulator (not the devices)" for p in summary["evaluation"])
    # on the simulator nothing is labelled
    sim = tmp_path / "sim"
    assert main(["run", str(script), "--out", str(sim), "--no-plots"]) == 0
    assert "simulated" not in capsys.readouterr().out
    assert json.loads((sim / "summary.json").read_text())["where"]["learning"] == "simulator"
