"""The simulated head: deterministic motion in simulated time, scripts, safety, shut-down."""

from __future__ import annotations

import pytest

from head import DIRECTIONS, SimHead, open_head
from head.errors import HeadClosed, HeadError, UnknownDirection, UnknownProtocol, UnknownResponse


def test_open_head_sim_is_a_sim_head_at_centre_using_the_shipped_calibration():
    with open_head("sim") as head:
        assert isinstance(head, SimHead)
        assert head.calibration.name == "Dr Robot WHA8030"
        assert head.looking_at() == "centre"


@pytest.mark.parametrize("direction", DIRECTIONS)
def test_look_reaches_every_direction(fast_cal, direction):
    with SimHead(fast_cal) as head:
        head.look(direction)
        assert head.wait() is True
        assert head.looking_at() == direction
        assert head.positions() == {n: float(v) for n, v in fast_cal.pose_of(direction).items()}


def test_motion_takes_distance_over_calibrated_speed():
    head = SimHead()  # neck_pan 1500 -> 1850 at 600 us/s; eye_pan 100 at 1200 us/s
    head.look("left")
    assert head.is_moving() and head.looking_at() is None
    head.tick(0.25)
    pos = head.positions()
    assert pos["neck_pan"] == pytest.approx(1500 + 600 * 0.25)
    assert pos["eye_pan"] == pytest.approx(1600)  # already there
    head.tick(0.25)
    assert head.is_moving()
    head.tick(350 / 600 - 0.5)
    assert not head.is_moving()
    assert head.looking_at() == "left"
    arrived = [e for e in head.events if e.kind == "arrived"]
    assert arrived[-1].time == pytest.approx(350 / 600)
    assert arrived[-1].direction == "left"
    head.close()


def test_wait_with_a_short_timeout_returns_false_and_time_advances_exactly():
    head = SimHead()
    head.look("right")
    assert head.wait(timeout=0.1) is False
    assert head.time == pytest.approx(0.1)
    assert head.wait() is True
    assert head.time == pytest.approx(350 / 600)


def test_speed_argument_can_only_slow_a_servo_down(fast_cal):
    head = SimHead(fast_cal)
    head.move_to({"neck_pan": 1600}, speed=100)
    head.wait()
    assert head.time == pytest.approx(1.0)
    head.move_to({"neck_pan": 1700}, speed=1e9)  # capped at the calibrated 10000 us/s
    head.wait()
    assert head.time == pytest.approx(1.01)
    with pytest.raises(HeadError, match="speed"):
        head.move_to({"neck_pan": 1500}, speed=0)


def test_same_script_same_events():
    def run():
        head = SimHead()
        for response in ("look(left_down)", "name_object", "look(centre)", "look(right)"):
            head.emit(response)
        head.close()
        return [(round(e.time, 9), e.kind, e.direction, e.pose) for e in head.events]

    assert run() == run()


def test_name_object_nods_towards_the_object_and_comes_back():
    head = SimHead()
    head.emit("look(left_down)")
    start = dict(head.targets)
    seen = []
    head.on_event = lambda e: seen.append(e)
    head.emit("name_object")
    moves = [e.pose for e in seen if e.kind == "move"]
    assert len(moves) == 4
    assert moves[0]["neck_tilt"] == start["neck_tilt"] - 60  # nod down
    assert moves[0]["mouth"] > start["mouth"]  # mouth opens while speaking
    assert moves[-1] == start
    assert head.looking_at() == "left_down"
    assert head.time > 0.5 + 3 * 0.12  # the holds take simulated time


def test_unknown_response_and_direction_are_clear_errors():
    head = SimHead()
    with pytest.raises(UnknownResponse, match=r"no motor script for response 'wave'"):
        head.emit("wave")
    with pytest.raises(UnknownDirection, match="up"):
        head.look("up")


def test_out_of_range_poses_are_clamped_and_counted(fast_cal):
    head = SimHead(fast_cal)
    sent = head.move_to({"neck_pan": 5000, "neck_tilt": -100})
    assert sent == {"neck_pan": 2000, "neck_tilt": 1200}
    assert head.status()["clamped"] == 2
    head.wait()
    assert head.positions()["neck_pan"] == 2000


def test_close_returns_to_centre_is_safe_twice_and_reopen_works(fast_cal):
    head = SimHead(fast_cal)
    head.look("right")
    head.wait()
    head.close()
    assert head.closed
    assert head.positions() == {n: float(v) for n, v in fast_cal.centre_pose().items()}
    head.close()
    with pytest.raises(HeadClosed, match="reopen"):
        head.look("left")
    head.reopen()
    head.look("left")
    head.wait()
    assert head.looking_at() == "left"


def test_context_manager_keeps_the_original_exception(fast_cal):
    with pytest.raises(ZeroDivisionError), SimHead(fast_cal) as head:
        head.look("down")
        raise ZeroDivisionError("inside the with block")
    assert head.closed


def test_tick_refuses_negative_time():
    with pytest.raises(ValueError):
        SimHead().tick(-1)


def test_sim_checks_the_protocol_name_anyway():
    with pytest.raises(UnknownProtocol, match="did you mean 'maestro'"):
        open_head("sim", "maestro2")


def test_partial_move_does_not_stop_servos_still_moving(fast_cal):
    """Bug found by the property tests: a move of one servo froze the others mid-way."""
    head = SimHead(fast_cal)
    head.move_to({"neck_pan": 2000, "neck_tilt": 1800}, speed=100)  # 5 s and 3 s
    head.tick(1.0)
    head.move_to({"eye_pan": 1600})
    assert head.wait(timeout=10.0)
    assert head.positions()["neck_pan"] == 2000.0
    assert head.positions()["neck_tilt"] == 1800.0
    assert head.time == pytest.approx(5.0)
