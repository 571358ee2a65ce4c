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
from relrl.episodes.recording import FrameRecorder
from relrl.monitor.frames import decode_jpeg
from tests.monitor.conftest import episode


def test_frames_round_trip(tmp_path: Path) -> None:
    frames = [render(SceneView(place, "frontal", {"left": "apple"}, 1.0, k))
              for k, place in enumerate(["centre", "left", "down", "right"])]
    rec = FrameRecorder(tmp_path, rate=0, quality=90)
    for t, frame in enumerate(frames, 1):
        assert rec.add(frame, t, "centre") == t
    rec.close()
    rec.close()  # safe twice
    index = [json.loads(x) for x in (tmp_path / "frames.jsonl").read_text().splitlines()]
    assert [e["t"] for e in index] == [1, 2, 3, 4]
    assert rec.bytes == sum((tmp_path / e["file"]).stat().st_size for e in index)
    camera = open_camera(str(tmp_path))  # a folder with frames.jsonl: the recording source
    for frame in frames:
        back = camera.read()
        assert back.shape == frame.shape
        err = np.abs(back.astype(int) - frame.astype(int)).mean()
        psnr = 10 * np.log10(255 ** 2 / np.mean((back.astype(float) - frame) ** 2))
        assert err < 3 and psnr > 30, (err, psnr)
    assert camera.read() is None
    decoded = decode_jpeg((tmp_path / index[0]["file"]).read_bytes())
    assert decoded.shape == frames[0].shape


def test_the_rate_limits_recorded_frames(tmp_path: Path) -> None:
    rec = FrameRecorder(tmp_path, rate=1.0)
    frame = np.zeros((8, 8, 3), np.uint8)
    kept = 0
    for t in range(50):
        if rec.due():
            rec.add(frame, t, None)
            kept += 1
    rec.close()
    assert kept == 1  # 50 time units within far less than a second: one frame


def test_recorded_frames_are_perceived_again(tmp_path: Path) -> None:
    script = episode(tmp_path, steps=40)
    out = tmp_path / "rec"
    assert main(["run", str(script), "--out", str(out), "--record", "--record-rate", "0",
                 "--record-quality", "95", "--no-plots"]) == 0
    rows = [json.loads(x) for x in (out / "trace.jsonl").read_text().splitlines()]
    index = [json.loads(x) for x in (out / "frames.jsonl").read_text().splitlines()]
    assert len(index) == 41 and [r["frame"] for r in rows] == list(range(1, 41))
    for key in ("percepts", "memory", "memory_size", "activation", "necessity", "reward",
                "response", "explanation", "head", "metrics", "overlay"):
        assert key in rows[0], key
    assert all(isinstance(a, int) and isinstance(e, str) for a, e in rows[5]["memory"])
    # perception run again on the recorded frames gives the facts the robot decided on
    perceiver = Perceiver()
    camera = open_camera(f"recording://{out}")
    same = 0
    for row, entry in zip(rows, index, strict=False):
        facts = perceiver.perceive(camera.read(), looking_at=entry["looking_at"])
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
    with pytest.raises(CameraError, match="frames.jsonl"):
        open_camera(f"recording://{tmp_path}")
    assert main(["replay", str(tmp_path)]) == 2


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
