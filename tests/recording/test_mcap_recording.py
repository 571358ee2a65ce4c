"""A recorded session read back by independent readers: every channel with the ``mcap``
library's reader and its schema's decoder (mcap-ros2-support for CDR, jsonschema for JSON);
a session killed with ``kill -9`` leaves a file readable up to its last chunk; damaged files
are one line; old folders migrate; ``relrl replay FILE.mcap``."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import cv2
import jsonschema
import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from relrl.cli import main
from relrl.recording.channels import CHANNELS
from relrl.recording.reader import McapRecording
from tests.monitor.conftest import episode
from tests.recording.foxglove_proto import protobuf_decoder

pytestmark = pytest.mark.slow  # every test here takes a second or more

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> Path:
    """A 40-unit session on the simulated head with rendered frames, every frame recorded,
    two evaluations."""
    tmp = tmp_path_factory.mktemp("rec")
    script = episode(tmp, steps=40, extra="[evaluation]\nevery = 20\nruns = 1\nsteps = 10\n")
    out = tmp / "session"
    assert main(["run", str(script), "--out", str(out), "--head", "sim", "--record",
                 "--record-rate", "0", "--no-plots"]) == 0
    return out


def test_every_channel_reads_back_with_its_schema(recorded: Path) -> None:
    trace = [json.loads(x) for x in (recorded / "trace.jsonl").read_text().splitlines()]
    by_topic: dict[str, list] = {}
    with open(recorded / "session.mcap", "rb") as fh:
        reader = make_reader(fh, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None and summary.chunk_indexes  # chunked and indexed
        for schema, channel, message in reader.iter_messages():
            if channel.message_encoding == "json":
                msg = json.loads(message.data)
                jsonschema.validate(msg, json.loads(schema.data))
            elif channel.message_encoding == "protobuf":  # Foxglove's, by protobuf's reader
                assert schema.encoding == "protobuf"
                msg = protobuf_decoder(schema)(message.data)
            else:
                assert channel.message_encoding == "cdr" and schema.encoding == "ros2msg"
                msg = DecoderFactory().decoder_for("cdr", schema)(message.data)
            by_topic.setdefault(channel.topic, []).append((message.log_time, msg, schema))
        meta = {m.name: json.loads(m.metadata["json"]) for m in reader.iter_metadata()}
        attached = {a.name for a in reader.iter_attachments()}
    assert set(by_topic) == {c.topic for c in CHANNELS}  # every channel has messages
    for ch in CHANNELS:
        assert by_topic[ch.topic][0][2].name == ch.schema
    n = len(trace)
    for topic in ("/relrl/percepts", "/relrl/working_memory", "/relrl/necessities",
                  "/relrl/reward", "/relrl/response", "/relrl/head", "/relrl/interaction",
                  "/head/joint_states"):
        assert len(by_topic[topic]) == n, topic
    assert [m["percepts"] for _, m, _ in by_topic["/relrl/percepts"]] == \
        [r["percepts"] for r in trace]
    assert [m["reward"] for _, m, _ in by_topic["/relrl/reward"]] == [r["reward"] for r in trace]
    assert by_topic["/relrl/response"][-1][1]["explanation"] == trace[-1]["explanation"]
    # one clock: a unit's messages share its log time; the image's stamp is that time
    units = [ns for ns, _, _ in by_topic["/relrl/percepts"]]
    assert units == sorted(units)
    assert [ns for ns, _, _ in by_topic["/relrl/reward"]] == units
    images = by_topic["/camera/image/compressed"]
    assert len(images) == n + 1  # every unit's frame and the last view
    for ns, img, _ in images[:3]:
        assert img.format == "jpeg" and img.header.frame_id == "camera"
        assert img.header.stamp.sec * 10**9 + img.header.stamp.nanosec == ns
        frame = cv2.imdecode(np.frombuffer(bytes(img.data), np.uint8), cv2.IMREAD_COLOR)
        assert frame.shape == (240, 320, 3)
    assert [ns for ns, _, _ in images[:n]] == units
    ann = by_topic["/camera/annotations"]
    assert len(ann) == len(images) and any(a.points and a.texts for _, a, _ in ann)
    ns, drawn = next((ns, a) for ns, a, _ in ann if a.points)  # on its image's time
    assert drawn.points[0].timestamp.seconds * 10**9 + drawn.points[0].timestamp.nanos == ns
    joints = by_topic["/head/joint_states"][0][1]
    assert list(joints.name) == sorted(trace[0]["head"]["servos"])
    assert by_topic["/relrl/tree"][-1][1]["graph"]["nodes"]
    assert [e["kind"] for _, e, _ in by_topic["/relrl/events"]] == ["evaluation"] * 3
    assert by_topic["/relrl/session"][0][1]["necessities"] == ["socialize"]
    assert meta["relrl.session"]["episode"] == "short" and "cgi" in meta["relrl.summary"]
    assert attached == {"episode.toml", "domain.pl"}
    # and relrl's own reader gives the trace back, row for row
    assert McapRecording(recorded / "session.mcap").rows == trace


def test_replay_an_mcap_file(recorded: Path) -> None:
    out = subprocess.run([sys.executable, "-m", "relrl", "replay",
                          str(recorded / "session.mcap"), "--seconds", "0.5"],
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    assert "40 time units, 41 frames" in out.stdout


def _replay_says(path: Path) -> str:
    out = subprocess.run([sys.executable, "-m", "relrl", "replay", str(path),
                          "--seconds", "0.1"],
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 2, out
    assert "Traceback" not in out.stderr and len(out.stderr.strip().splitlines()) == 1
    return out.stderr


def test_bad_recordings_are_one_line(recorded: Path, tmp_path: Path) -> None:
    data = (recorded / "session.mcap").read_bytes()
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not an mcap file at all")
    assert "not an MCAP file" in _replay_says(junk)
    with open(recorded / "session.mcap", "rb") as fh:
        chunk = make_reader(fh).get_summary().chunk_indexes[-1]  # one or more, by timing
    damaged = tmp_path / "damaged.mcap"
    inside = bytearray(data)  # bytes flipped inside a chunk's compressed messages
    for i in range(chunk.chunk_start_offset + 200, chunk.chunk_start_offset + 264):
        inside[i] ^= 0xFF
    damaged.write_bytes(bytes(inside))
    assert "damaged MCAP file" in _replay_says(damaged)
    head_only = tmp_path / "head.mcap"
    head_only.write_bytes(data[:40])
    assert "cut short before its first complete chunk" in _replay_says(head_only)
    assert "no such file" in _replay_says(tmp_path / "missing.mcap")


def test_damage_anywhere_is_never_a_traceback(recorded: Path, tmp_path: Path) -> None:
    """Bytes flipped at ten places through the file: one line and exit 2, or (a length
    field made to run past the end) read as cut short, with a note, or (the summary's index
    hit) read whole from its messages; never a traceback."""
    data = (recorded / "session.mcap").read_bytes()
    for k in range(1, 11):
        bad = bytearray(data)
        at = len(data) * k // 11
        for i in range(at, min(at + 16, len(data))):
            bad[i] ^= 0x5A
        path = tmp_path / f"bad{k}.mcap"
        path.write_bytes(bytes(bad))
        out = subprocess.run([sys.executable, "-m", "relrl", "replay", str(path),
                              "--seconds", "0.1"], capture_output=True, text=True,
                             timeout=120, cwd=ROOT)
        assert "Traceback" not in out.stderr, (k, out.stderr)
        assert out.returncode in (0, 2) and len(out.stderr.strip().splitlines()) <= 1, k
        if out.returncode == 0:  # read as cut, or the damage was in the summary's index
            assert "cut short" in out.stderr or "40 time units, 41 frames" in out.stdout


def _session_killed(tmp_path: Path, name: str, writer_too: bool) -> Path:
    """A recorded session killed with SIGKILL a few seconds in (and its writer process with
    it, first, when ``writer_too``)."""
    script = episode(tmp_path, steps=5000)
    out = tmp_path / name
    proc = subprocess.Popen([sys.executable, "-m", "relrl", "-q", "run", str(script), "--out",
                             str(out), "--record", "--record-rate", "0", "--no-plots"],
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    path = out / "session.mcap"
    writer = None
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline:  # a few seconds of session: a few chunks
            if path.is_file() and path.stat().st_size > 60_000:
                break
            time.sleep(0.2)
        time.sleep(1.5)
        children = Path(f"/proc/{proc.pid}/task/{proc.pid}/children").read_text().split()
        writer = int(children[0])
        if writer_too:
            os.kill(writer, signal.SIGKILL)
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(30)
    assert proc.returncode == -signal.SIGKILL
    deadline = time.monotonic() + 30  # the writer, left alone, ends at the end of its input
    while Path(f"/proc/{writer}").exists() and time.monotonic() < deadline:
        try:
            os.waitpid(writer, os.WNOHANG)
        except ChildProcessError:
            pass
        if Path(f"/proc/{writer}/stat").exists() and \
                Path(f"/proc/{writer}/stat").read_text().split()[2] == "Z":
            break
        time.sleep(0.1)
    return out


def test_kill_9_of_session_and_writer_leaves_a_file_readable_to_its_last_chunk(
        tmp_path: Path) -> None:
    from mcap.exceptions import EndOfFile
    from mcap.reader import NonSeekingReader

    out = _session_killed(tmp_path, "killed", writer_too=True)
    path = out / "session.mcap"
    # the mcap library's own stream reader reads it up to where it was cut
    counts: dict[str, int] = {}
    with open(path, "rb") as fh:
        try:
            for _, channel, _ in NonSeekingReader(fh, validate_crcs=True).iter_messages(
                    log_time_order=False):
                counts[channel.topic] = counts.get(channel.topic, 0) + 1
        except EndOfFile:
            pass
    assert counts.get("/relrl/percepts", 0) >= 5 and counts.get("/camera/image/compressed")
    rec = McapRecording(path)
    assert rec.cut and "cut short" in rec.cut
    trace = [json.loads(x) for x in (out / "trace.jsonl").read_text().splitlines() if x]
    assert 5 <= len(rec.rows) <= len(trace)
    assert rec.rows == trace[:len(rec.rows)]  # whole time units, as the trace has them
    assert rec.frame_bytes(len(rec.frames)) is not None
    replay = subprocess.run([sys.executable, "-m", "relrl", "replay", str(out), "--seconds",
                             "0.3"], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert replay.returncode == 0, replay.stderr
    assert "cut short" in replay.stderr


def test_kill_9_of_the_session_leaves_a_complete_file(tmp_path: Path) -> None:
    """The writer process sees its input end and closes the file with its summary: every
    unit handed over is in it (the trace may hold the last few more)."""
    out = _session_killed(tmp_path, "killed", writer_too=False)
    with open(out / "session.mcap", "rb") as fh:
        assert make_reader(fh).get_summary() is not None  # complete: summary and footer
    rec = McapRecording(out / "session.mcap")
    assert rec.cut is None
    trace = [json.loads(x) for x in (out / "trace.jsonl").read_text().splitlines() if x]
    assert len(trace) - 30 <= len(rec.rows) <= len(trace) and len(rec.rows) >= 5
    assert rec.rows == trace[:len(rec.rows)]


def _old_folder(tmp_path: Path) -> Path:
    """A session recorded as a folder of frames, as earlier relrl wrote it."""
    from perception.render import SceneView, render
    from relrl.monitor.frames import encode_jpeg

    script = episode(tmp_path, steps=12)
    old = tmp_path / "old"
    assert main(["run", str(script), "--out", str(old), "--no-plots"]) == 0
    rows = [json.loads(x) for x in (old / "trace.jsonl").read_text().splitlines()]
    (old / "frames").mkdir()
    index = []
    for k, t in enumerate(range(1, 13, 3), 1):
        data = encode_jpeg(render(SceneView("centre", "frontal", {}, 1.0, k)), 85)
        (old / "frames" / f"{k:06d}.jpg").write_bytes(data)
        index.append({"index": k, "t": t, "file": f"frames/{k:06d}.jpg",
                      "looking_at": "centre"})
        rows[t - 1]["frame"] = k
    (old / "trace.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    (old / "frames.jsonl").write_text("".join(json.dumps(e) + "\n" for e in index))
    (old / "trees.jsonl").write_text(json.dumps({"t": 0, "graph": {"nodes": [
        {"id": "0", "kind": "leaf", "label": ""}], "edges": []}}) + "\n")
    (old / "events.jsonl").write_text(json.dumps({"kind": "evaluation", "t": 6,
                                                  "cgi_mean": 0.5}) + "\n")
    (old / "session.json").write_text(json.dumps({"episode": "short", "seconds": 3.0,
                                                  "recorded": "2025-03-02T10:14:05+0000",
                                                  "necessities": ["socialize"]}))
    return old


def test_migrate_an_old_folder(tmp_path: Path) -> None:
    old = _old_folder(tmp_path)
    from perception.camera import open_camera
    from perception.errors import CameraError

    with pytest.raises(CameraError, match="relrl migrate"):  # told how, not guessed
        open_camera(str(old))
    replay = subprocess.run([sys.executable, "-m", "relrl", "replay", str(old), "--seconds",
                             "0.1"], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert replay.returncode == 0 and "12 time units, 4 frames" in replay.stdout  # as before
    before = {p.name: p.read_bytes() for p in old.rglob("*") if p.is_file()}
    out = subprocess.run([sys.executable, "-m", "relrl", "migrate", str(old)],
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    after = {p.name: p.read_bytes() for p in old.rglob("*") if p.is_file()}
    assert {k: v for k, v in after.items() if k != "session.mcap"} == before  # all kept
    rec = McapRecording(old / "session.mcap")
    trace = [json.loads(x) for x in (old / "trace.jsonl").read_text().splitlines()]
    assert rec.rows == trace
    assert [f["t"] for f in rec.frames] == [1, 4, 7, 10]
    assert rec.frame_bytes(2) == (old / "frames" / "000002.jpg").read_bytes()
    assert rec.events == [{"kind": "evaluation", "t": 6, "cgi_mean": 0.5}]
    assert rec.tree_at(5)["nodes"][0]["kind"] == "leaf"
    assert rec.rows[-1] and rec.manifest["episode"] == "short"
    with open_camera(str(old)) as camera:  # now the folder's session.mcap, every frame
        assert sum(1 for _ in camera) == 4
    t0 = rec.frames[0]["log_time"]
    assert abs(t0 / 1e9 - 1740910445.0) < 1.0  # on the session's recorded clock
    again = subprocess.run([sys.executable, "-m", "relrl", "migrate", str(old)],
                           capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert again.returncode == 2 and "already there" in again.stderr


def test_the_file_is_never_a_link_nor_written_over(tmp_path: Path) -> None:
    from relrl.errors import OutputError
    from relrl.recording.recorder import Recorder

    (tmp_path / "elsewhere.txt").write_text("keep me")
    (tmp_path / "session.mcap").symlink_to(tmp_path / "elsewhere.txt")
    rec = Recorder()
    try:
        with pytest.raises(OutputError, match="a link is there"):
            rec.open(tmp_path / "session.mcap")
        rec.open(tmp_path / "other.mcap")  # the writer is still there for a good path
        assert rec.close_file() > 0
    finally:
        rec.close()
        rec.close()  # safe twice
    assert (tmp_path / "elsewhere.txt").read_text() == "keep me"


def test_a_writer_that_dies_is_one_line_in_the_session(tmp_path: Path) -> None:
    from relrl.errors import OutputError
    from relrl.recording.recorder import Recorder

    rec = Recorder()
    rec.open(tmp_path / "s.mcap")
    rec._proc.kill()
    rec._proc.wait()
    with pytest.raises(OutputError, match="the recording's writer stopped"):
        for t in range(10_000):  # the pipe breaks at the first flush
            rec.unit(time.time_ns(), b'{"t":%d}' % t)
    rec.close()  # reported once, when it happened; closing only cleans up
    rec.close()


def _handmade(path: Path, rows: list[dict[str, Any]]) -> Path:
    """An MCAP file written with the ``mcap`` library alone: one JSON message per row
    channel and time unit (no relrl writer involved)."""
    from mcap.writer import Writer

    from relrl.recording.channels import ROW_CHANNELS

    with open(path, "wb") as fh:
        w = Writer(fh)
        w.start()
        ids = {}
        for ch in ROW_CHANNELS:
            schema = w.register_schema(ch.schema, ch.schema_encoding, ch.schema_data)
            ids[ch.topic] = w.register_channel(ch.topic, "json", schema)
        for i, row in enumerate(rows):
            for ch in ROW_CHANNELS:
                part = {"t": row["t"], **{k: row[k] for k in ch.keys if k in row}}
                w.add_message(ids[ch.topic], log_time=i, publish_time=i, data=json.dumps(
                    part).encode())
        w.finish()
    return path


def test_an_mcap_file_is_checked_as_a_folder_is(tmp_path: Path) -> None:
    """The replay's shapes (relrl.monitor.schema) apply to an MCAP recording's rows: a
    wrong type is one line naming the file and the time unit, never a 500 later."""
    good = {"t": 0, "activation": {"socialize": 0.5}, "reward": 1.0, "percepts": []}
    assert McapRecording(_handmade(tmp_path / "ok.mcap", [good])).rows[0]["reward"] == 1.0
    bad = _handmade(tmp_path / "bad.mcap", [good, {**good, "t": 1, "activation": "high"}])
    said = _replay_says(bad)
    assert "bad.mcap" in said and "time unit 1" in said and "activation" in said
    nested = _handmade(tmp_path / "nested.mcap", [{**good, "percepts": [[[[[]]]]]}])
    assert McapRecording(nested).rows  # lists nest as a folder's do
