"""``relrl head``: look, emit, status, calibrate from piped keys, one-line errors."""

from __future__ import annotations

import io
import json

from head.calibration import load_calibration
from head.fake import FakeController, PtyController
from relrl.cli import main


def test_look_on_the_simulated_head(capsys):
    assert main(["head", "--port", "sim", "look", "left_down"]) == 0
    assert capsys.readouterr().out.strip() == "looking at left_down"


def test_emit_and_status_json(capsys):
    assert main(["head", "emit", "look(right)"]) == 0
    assert "looking at right" in capsys.readouterr().out
    assert main(["head", "status", "--json"]) == 0
    status = json.loads(capsys.readouterr().out)
    assert status["looking_at"] == "centre" and status["errors"] == []


def test_status_through_a_fake_maestro(capsys, fast_path):
    fake = FakeController("maestro")
    with PtyController(fake) as pty:
        fake.error_bits = 1 << 5
        code = main(["head", "--port", pty.port, "--protocol", "maestro",
                     "--calibration", str(fast_path), "status"])
    out = capsys.readouterr().out
    assert code == 0
    assert "errors: serial timeout" in out and "protocol: maestro" in out
    assert fake.violations == []


def test_missing_device_is_one_line_and_exit_2(capsys):
    code = main(["head", "--port", "/dev/ttyNOPE0", "--protocol", "ssc32", "look", "left"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "cannot open serial port '/dev/ttyNOPE0'" in err


def test_bad_direction_protocol_and_calibration_exit_2(capsys, tmp_path):
    assert main(["head", "look", "up"]) == 2
    assert "unknown direction 'up'" in capsys.readouterr().err
    assert main(["head", "--protocol", "ssc33", "status"]) == 2
    assert "did you mean 'ssc32'" in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text("[servos.x]\nchannel = 0\n")
    assert main(["head", "--calibration", str(bad), "status"]) == 2
    assert f"{bad}: servos.x" in capsys.readouterr().err


def test_calibrate_from_piped_keys_writes_a_valid_file(capsys, monkeypatch, tmp_path,
                                                       fast_path):
    out = tmp_path / "mine.toml"
    # neck_pan: 5 steps of 10 down -> min 1450; back up 10 steps -> max 1550; next servo;
    # step 25, two up -> neck_tilt max 1550; then an impossible centre, then write.
    keys = "----- m\n++++++++++ x\n n ] ++ x + c w\n"
    monkeypatch.setattr("sys.stdin", io.StringIO(keys))
    code = main(["head", "--calibration", str(fast_path), "calibrate", "-o", str(out)])
    text = capsys.readouterr().out
    assert code == 0, text
    assert f"wrote {out}" in text
    cal = load_calibration(out)
    pan, tilt = cal.servos["neck_pan"], cal.servos["neck_tilt"]
    assert (pan.min, pan.centre, pan.max) == (1450, 1500, 1550)
    assert (tilt.min, tilt.centre, tilt.max) == (1200, 1500, 1550)
    assert "not set: neck_tilt needs min < centre < max, would be 1200 / 1575 / 1550" in text
    assert cal.directions["left"]["neck_pan"] == 1550  # clamped into the new range
    assert "clamped into the new range" in text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fast.toml", "mine.toml"]


def test_calibrate_quit_writes_nothing(capsys, monkeypatch, tmp_path, fast_path):
    monkeypatch.setattr("sys.stdin", io.StringIO("--- m q"))
    before = fast_path.read_text()
    assert main(["head", "--calibration", str(fast_path), "calibrate"]) == 0
    assert "quit without writing (changes discarded)" in capsys.readouterr().out
    assert fast_path.read_text() == before
