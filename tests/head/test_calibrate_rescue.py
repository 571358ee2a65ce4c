"""Calibration never loses the jogged limits: a file that cannot be written, a port lost
while jogging, or Ctrl-C leave them in head-rescued-*.toml (and the message says where)."""

from __future__ import annotations

import io

import pytest

from head import SimHead
from head.calibrate import calibrate
from head.calibration import load_calibration, save_calibration
from head.errors import CalibrationError, PortLost


class Keys:
    """Key presses, then ``then`` raised when they run out (a lost port, Ctrl-C)."""

    def __init__(self, keys: str, then: BaseException) -> None:
        self.keys = keys
        self.then = then

    def __iter__(self):
        yield self.keys
        raise self.then


@pytest.fixture
def rescued(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return lambda: sorted(tmp_path.glob("head-rescued-*.toml"))


def test_a_file_that_cannot_be_written_is_rescued(fast_cal, tmp_path, rescued, monkeypatch):
    target = tmp_path / "wanted.toml"

    def refuse(cal, path):
        if path == target:
            raise CalibrationError(f"cannot write the calibration to {path}: disk full")
        return save_calibration(cal, path)

    monkeypatch.setattr("head.calibrate.save_calibration", refuse)
    out = io.StringIO()
    with pytest.raises(CalibrationError, match="disk full; the limits set so far were saved "
                                               "to .*head-rescued-"):
        calibrate(SimHead(fast_cal), io.StringIO("----- m w"), out, target)
    (path,) = rescued()
    assert load_calibration(path).servos["neck_pan"].min == 1450


@pytest.mark.parametrize("then", [PortLost("lost serial port 'x'"), KeyboardInterrupt()])
def test_limits_set_before_a_lost_port_or_ctrl_c_are_rescued(fast_cal, rescued, then):
    out = io.StringIO()
    with pytest.raises(type(then)) as info:
        calibrate(SimHead(fast_cal), Keys("+++++ x", then), out, "never.toml")
    (path,) = rescued()
    assert load_calibration(path).servos["neck_pan"].max == 1550
    said = str(info.value) if isinstance(then, PortLost) else out.getvalue()
    assert f"the limits set so far were saved to {path}" in said


def test_nothing_set_nothing_rescued(fast_cal, rescued):
    with pytest.raises(KeyboardInterrupt):
        calibrate(SimHead(fast_cal), Keys("+++", KeyboardInterrupt()), io.StringIO(), "x.toml")
    assert rescued() == []


@pytest.mark.parametrize("name", ["adir", "/dev/null"])
def test_save_calibration_writes_only_regular_files(fast_cal, tmp_path, name):
    (tmp_path / "adir").mkdir()
    target = tmp_path / name if name == "adir" else name
    with pytest.raises(CalibrationError, match="not a regular file"):
        save_calibration(fast_cal, target)
    assert list(tmp_path.glob(".*.tmp")) == []
