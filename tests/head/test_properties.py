"""Property tests: no input puts a pulse outside the calibrated range on the wire.

For every protocol, hypothesis draws a calibration (channels, limits, speeds, direction
poses, scripts with wild offsets) and a sequence of commands with any numbers at all; the
bytes the head writes go to a fake controller that decodes them independently, and every
decoded pulse must lie inside that servo's calibrated [min, max].
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from head.calibration import DIRECTIONS, Calibration, Servo, load_calibration, save_calibration
from head.errors import HeadError
from head.fake import FakeController, FakeSerial
from head.protocols import get_protocol
from head.scripts import MotorScript, Step
from head.serial_head import SerialHead
from head.sim import SimHead

pytestmark = pytest.mark.slow  # every test here takes a second or more

PROFILE = settings(max_examples=150, deadline=None,
                   suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
NAMES = ["neck_pan", "neck_tilt", "eye_pan", "eye_tilt", "mouth"]
wild = st.one_of(
    st.integers(min_value=-10**9, max_value=10**9),
    st.floats(allow_nan=False, allow_infinity=False, min_value=-1e12, max_value=1e12),
    st.sampled_from([499, 500, 2500, 2501, 0, -1, 65535, 1e300]),
)


@st.composite
def servo_limits(draw):
    lo = draw(st.integers(500, 2480))
    hi = draw(st.integers(lo + 2, 2500))
    centre = draw(st.integers(lo + 1, hi - 1))
    return lo, centre, hi


@st.composite
def calibrations(draw, max_channel: int):
    n = draw(st.integers(1, 5))
    channels = draw(st.lists(st.integers(0, max_channel), min_size=n, max_size=n, unique=True))
    servos = {}
    for name, ch in zip(NAMES[:n], channels, strict=True):
        lo, centre, hi = draw(servo_limits())
        speed = draw(st.floats(25.0, 20000.0))
        accel = draw(st.integers(0, 255))
        servos[name] = Servo(name, ch, lo, centre, hi, speed, accel)
    directions = {}
    for d in DIRECTIONS:
        directions[d] = {s.name: draw(st.integers(s.min, s.max)) for s in servos.values()}
    offsets = st.dictionaries(st.sampled_from(list(servos)), wild, max_size=n)
    steps = st.lists(st.one_of(
        st.builds(lambda v, sp: Step("offset", values=v, speed=sp), offsets,
                  st.none() | st.floats(0.5, 1e9)),
        st.builds(lambda d: Step("direction", direction=d), st.sampled_from(DIRECTIONS)),
    ), min_size=1, max_size=4)
    scripts = {"nod": MotorScript("nod", tuple(draw(steps)))}
    return Calibration(servos, directions, scripts, "random head")


def commands(cal: Calibration):
    pose = st.dictionaries(st.sampled_from(list(cal.servos)), wild, max_size=len(cal.servos))
    speed = st.none() | st.floats(0.01, 1e9)
    return st.lists(st.one_of(
        st.tuples(st.just("move"), pose, speed),
        st.tuples(st.just("look"), st.sampled_from(DIRECTIONS), st.none()),
        st.tuples(st.just("emit"), st.just("nod"), st.none()),
    ), max_size=8)


class FakeClock:
    """Time that passes only when slept (the fake controller shares it)."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now

    def sleep(self, dt: float) -> None:
        self.now += dt


def play(head, ops) -> None:
    for kind, arg, speed in ops:
        if kind == "move":
            head.move_to(arg, speed)
        elif kind == "look":
            head.look(arg)
        else:
            head.emit(arg)
        head.wait(timeout=100.0)


def _check_wire(protocol: str, data) -> None:
    cal = data.draw(calibrations(get_protocol(protocol).max_channel), label="calibration")
    clock = FakeClock()
    limits = {s.channel: (s.min, s.max) for s in cal.servos.values()}
    fake = FakeController(protocol, limits=limits, clock=clock)
    port = FakeSerial(fake)
    head = SerialHead("fake://", protocol, cal, serial_factory=lambda *a, **k: port,
                      clock=clock, sleep=clock.sleep, feedback=True)
    ops = data.draw(commands(cal), label="commands")
    try:
        play(head, ops)
    finally:
        head.close()
    assert fake.violations == []
    assert fake.bytes_checked == len(port.written) == head.bytes_written
    for move in fake.moves:
        for ch, pulse in move.items():
            lo, hi = limits[ch]
            assert lo <= pulse <= hi, (ch, pulse, lo, hi)
    assert fake.moves, "opening and closing the head always moves to centre"
    centre = {s.channel: s.centre for s in cal.servos.values()}
    assert fake.moves[-1] == centre or protocol == "maestro"
    if protocol == "maestro":  # one target command per servo, the last ones are the centre
        assert {ch: round(fake.position(ch) * 4) / 4 for ch in centre} == {
            c: float(v) for c, v in centre.items()}


@PROFILE
@given(st.data())
def test_ssc32_never_writes_a_pulse_out_of_range(data):
    _check_wire("ssc32", data)


@PROFILE
@given(st.data())
def test_maestro_never_writes_a_pulse_out_of_range(data):
    _check_wire("maestro", data)


@PROFILE
@given(st.data())
def test_pms5005_never_writes_a_pulse_out_of_range(data):
    _check_wire("pms5005", data)


@PROFILE
@given(st.data())
def test_sim_head_never_leaves_the_calibrated_range(data):
    cal = data.draw(calibrations(31))
    head = SimHead(cal)
    for kind, arg, speed in data.draw(commands(cal)):
        play(head, [(kind, arg, speed)])
        for name, pos in head.positions().items():
            s = cal.servos[name]
            assert s.min <= pos <= s.max
    head.close()
    assert head.positions() == {n: float(s.centre) for n, s in cal.servos.items()}


@PROFILE
@given(st.data())
def test_non_numbers_are_refused_before_any_byte_is_written(data):
    cal = data.draw(calibrations(31))
    fake = FakeController("ssc32")
    port = FakeSerial(fake)
    head = SerialHead("fake://", "ssc32", cal, serial_factory=lambda *a, **k: port,
                      feedback=False)
    before = len(port.written)
    bad = data.draw(st.sampled_from([math.nan, math.inf, -math.inf, "1500", None, [1500]]))
    name = data.draw(st.sampled_from(list(cal.servos)))
    try:
        head.move_to({name: bad})
    except HeadError:
        pass
    else:
        raise AssertionError(f"{bad!r} was accepted")
    assert len(port.written) == before
    head.close(centre=False)


@settings(max_examples=60, deadline=None)
@given(calibrations(31))
def test_any_valid_calibration_survives_a_write_and_reload(cal):
    with tempfile.TemporaryDirectory() as tmp:
        again = load_calibration(save_calibration(cal, Path(tmp) / "head.toml"))
    assert again.servos == cal.servos
    assert again.directions == cal.directions
    for name, script in cal.scripts.items():
        assert [s.to_toml_inline() for s in again.scripts[name].steps] == [
            s.to_toml_inline() for s in script.steps]
