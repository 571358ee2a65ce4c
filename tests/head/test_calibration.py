"""Calibration files: loading, validation messages, writing back atomically."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from head.calibration import (
    DEFAULT_CALIBRATION,
    DIRECTIONS,
    dump_calibration,
    load_calibration,
    save_calibration,
)
from head.errors import CalibrationError, UnknownDirection, UnknownResponse, UnknownServo
from relrl.errors import USER_ERRORS


def test_shipped_wha8030_loads_with_five_servos_six_directions_and_scripts():
    cal = load_calibration()
    assert cal.path == DEFAULT_CALIBRATION
    assert len(cal.servos) == 5
    assert set(DIRECTIONS) <= set(cal.directions)
    for d in DIRECTIONS:
        assert f"look({d})" in cal.scripts
    assert "name_object" in cal.scripts
    assert cal.protocol == "pms5005"


def test_direction_poses_are_full_and_default_to_centre(fast_cal):
    assert fast_cal.directions["centre"] == fast_cal.centre_pose()
    assert fast_cal.directions["down"]["neck_pan"] == 1500
    assert fast_cal.directions["down"]["neck_tilt"] == 1250


BAD = [
    ("min = 1000\ncentre = 1500\nmax = 2000", "min = 1600\ncentre = 1500\nmax = 2000",
     "servos.neck_pan", "min < centre < max"),
    ("min = 1000\ncentre = 1500", "min = 400\ncentre = 1500", "servos.neck_pan.min", "500..2500"),
    ("max = 2000\nspeed = 10000", "max = 2600\nspeed = 10000", "servos.neck_pan.max", "2600"),
    ("speed = 8000", "speed = 0", "servos.neck_tilt.speed", "must be in 25..20000"),
    ("speed = 8000", "speed = -5", "servos.neck_tilt.speed", "-5"),
    ("speed = 8000", "speed = 10", "servos.neck_tilt.speed", "10 must be in 25"),
    ("speed = 8000", 'speed = "fast"', "servos.neck_tilt.speed", "'fast'"),
    ("channel = 5", "channel = 0", "servos.mouth.channel", "also used by neck_pan"),
    ("left = { neck_pan = 1900", "left = { nose = 1900", "directions.left.nose",
     "unknown servo"),
    ("down = { neck_tilt = 1250 }", "down = { neck_tilt = 1100 }", "directions.down.neck_tilt",
     "outside the calibrated range 1200..1800"),
    ("right = { neck_pan = 1100, eye_pan = 1400 }\n", "", "directions.right", "missing"),
    ('steps = [{ direction = "down" }]', 'steps = [{ direction = "up" }]',
     '"look(down)".steps[0].direction', "'up' is not a direction"),
    ('steps = [{ direction = "down" }]', "steps = [{ pose = { neck_pan = 2400 } }]",
     "pose.neck_pan", "outside the calibrated range"),
    ('steps = [{ direction = "down" }]', 'steps = [{ direction = "down", pose = {} }]',
     "steps[0]", "exactly one of"),
    ('steps = [{ direction = "down" }]', "steps = []", "steps", "non-empty"),
    ('steps = [{ direction = "down" }]', 'steps = [{ direction = "down", hold_ms = -1 }]',
     "hold_ms", "0..60000"),
    ("tolerance_us = 10", "tolerance_us = 10\ncolour = 1", "head.colour", "unknown key"),
    ("[head]", "[hed]\n[head]", "hed", "unknown table"),
    ("[head]", "[head", "not valid TOML", ""),
]


@pytest.mark.parametrize(("old", "new", "key", "text"), BAD)
def test_bad_calibration_is_one_line_naming_file_and_key(tmp_path, fast_toml, old, new, key,
                                                         text):
    assert old in fast_toml
    path = tmp_path / "bad.toml"
    path.write_text(fast_toml.replace(old, new, 1))
    with pytest.raises(CalibrationError) as info:
        load_calibration(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: ")
    assert key in message and text in message
    assert isinstance(info.value, USER_ERRORS)  # the command line prints one line, exit 2


def test_missing_file_is_a_calibration_error(tmp_path):
    with pytest.raises(CalibrationError, match="no such calibration file"):
        load_calibration(tmp_path / "nope.toml")


def test_clamp_limits_every_value_and_reports_which(fast_cal):
    pose, over = fast_cal.clamp({"neck_pan": 99999, "neck_tilt": -3.5, "eye_pan": 1510.6})
    assert pose == {"neck_pan": 2000, "neck_tilt": 1200, "eye_pan": 1511}
    assert over == ["neck_pan", "neck_tilt"]


@pytest.mark.parametrize("value", [float("nan"), float("inf"), "1500", None, True])
def test_clamp_refuses_values_that_are_not_numbers(fast_cal, value):
    with pytest.raises(UnknownServo):
        fast_cal.clamp({"neck_pan": value})


def test_unknown_names_list_the_known_ones(fast_cal):
    with pytest.raises(UnknownServo, match="known: neck_pan"):
        fast_cal.clamp({"nose": 1500})
    with pytest.raises(UnknownDirection, match="left_down"):
        fast_cal.pose_of("up")
    with pytest.raises(UnknownResponse, match=r"look\(left\)"):
        fast_cal.script_for("wave")


def test_response_text_is_normalised(fast_cal):
    assert fast_cal.script_for(" look( left ) ").response == "look(left)"


@pytest.mark.parametrize("source", ["fast", "shipped"])
def test_dump_then_load_gives_the_same_calibration(tmp_path, fast_path, source):
    cal = load_calibration(fast_path if source == "fast" else None)
    path = save_calibration(cal, tmp_path / "out.toml")
    again = load_calibration(path)
    assert again.servos == cal.servos
    assert again.directions == cal.directions
    assert again.scripts == cal.scripts
    assert (again.name, again.protocol, again.baudrate, again.tolerance_us) == (
        cal.name, cal.protocol, cal.baudrate, cal.tolerance_us)
    assert dump_calibration(again) == dump_calibration(cal)


def test_save_is_atomic_and_leaves_no_temporary_file(tmp_path, fast_cal):
    (tmp_path / "out").mkdir()
    target = tmp_path / "out" / "head.toml"
    target.write_text("old contents")
    save_calibration(fast_cal, target)
    assert load_calibration(target).servos == fast_cal.servos
    assert sorted(os.listdir(tmp_path / "out")) == ["head.toml"]


def test_save_of_an_invalid_calibration_keeps_the_old_file(tmp_path, fast_cal):
    from dataclasses import replace

    (tmp_path / "out").mkdir()
    target = tmp_path / "out" / "head.toml"
    save_calibration(fast_cal, target)
    before = target.read_text()
    bad = replace(fast_cal.servos["neck_pan"], min=1600)  # min above centre
    broken = replace(fast_cal, servos={**fast_cal.servos, "neck_pan": bad})
    with pytest.raises(CalibrationError, match="min < centre < max"):
        save_calibration(broken, target)
    assert target.read_text() == before
    assert sorted(os.listdir(tmp_path / "out")) == ["head.toml"]


def test_scripts_can_live_in_a_file_next_to_the_calibration(tmp_path: Path, fast_toml):
    (tmp_path / "more.toml").write_text(
        '[scripts."look(right)"]\nsteps = [{ direction = "right", hold_ms = 5 }]\n')
    text = fast_toml.replace('name = "fast test head"',
                             'name = "fast test head"\nscripts = "more.toml"')
    (tmp_path / "cal.toml").write_text(text)
    cal = load_calibration(tmp_path / "cal.toml")
    assert cal.script_for("look(right)").steps[0].hold_ms == 5
    # written back, the external scripts stay external
    save_calibration(cal, tmp_path / "cal2.toml")
    assert "look(right)" not in (tmp_path / "cal2.toml").read_text()
    assert load_calibration(tmp_path / "cal2.toml").scripts == cal.scripts


def test_a_script_defined_twice_is_an_error(tmp_path: Path, fast_toml):
    (tmp_path / "more.toml").write_text(
        '[scripts."look( left )"]\nsteps = [{ direction = "left" }]\n')
    text = fast_toml.replace('name = "fast test head"',
                             'name = "fast test head"\nscripts = "more.toml"')
    (tmp_path / "cal.toml").write_text(text)
    with pytest.raises(CalibrationError, match="more.toml.*also defined"):
        load_calibration(tmp_path / "cal.toml")


@pytest.mark.parametrize("scripts", ["/dev/zero", "fifo.toml", "adir", "p\u0000.toml"])
def test_a_scripts_file_that_is_no_file_is_refused_before_reading(tmp_path: Path, fast_toml,
                                                                   scripts: str):
    """``scripts = "/dev/zero"`` used to read without end (MemoryError); a pipe would block."""
    os.mkfifo(tmp_path / "fifo.toml")
    (tmp_path / "adir").mkdir()
    name = scripts.replace("\x00", "\\u0000")   # a NUL written as TOML's escape
    text = fast_toml.replace('name = "fast test head"',
                             f'name = "fast test head"\nscripts = "{name}"')
    (tmp_path / "cal.toml").write_text(text)
    with pytest.raises(CalibrationError, match=r"cal\.toml: head\.scripts: .*(cannot read: "
                                               r"(not a regular file|is a folder)|holds a NUL "
                                               r"character)"):
        load_calibration(tmp_path / "cal.toml")


@pytest.mark.parametrize("nest", ["[" * 3000 + "]" * 3000, "{ a = " * 3000 + "1" + " }" * 3000])
def test_a_calibration_nested_3000_deep_names_its_line(tmp_path: Path, fast_toml, nest: str):
    """It used to end in a RecursionError inside tomllib."""
    (tmp_path / "cal.toml").write_text(fast_toml + f"\n[extra]\nx = {nest}\n")
    line = fast_toml.count("\n") + 3
    with pytest.raises(CalibrationError, match=rf"cal\.toml:{line}: arrays or inline tables "
                                               r"nested more than 32 deep"):
        load_calibration(tmp_path / "cal.toml")


def test_a_calibration_larger_than_16_mb_is_refused(tmp_path: Path, fast_toml):
    (tmp_path / "cal.toml").write_text(fast_toml + "# " + "x" * (16 * 1024 * 1024) + "\n")
    with pytest.raises(CalibrationError, match=r"cal\.toml: cannot read: larger than 16 MB"):
        load_calibration(tmp_path / "cal.toml")
