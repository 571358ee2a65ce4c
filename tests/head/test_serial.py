"""The serial head against pyserial's loop:// and a fake controller behind a pseudo-terminal."""

from __future__ import annotations

import os
import socket
import threading
import time

import pytest

from head import open_head
from head.errors import HeadTimeout, PortLost, PortUnavailable
from head.fake import FakeController, PtyController
from head.serial_head import SerialHead

PROTOCOLS = ["ssc32", "maestro", "pms5005"]


def _settled(fake, count: int) -> int:
    """The fake's byte count once it has caught up with ``count`` (or after 2 s)."""
    deadline = time.monotonic() + 2.0
    while fake.bytes_checked < count and time.monotonic() < deadline:
        time.sleep(0.01)
    return fake.bytes_checked


def _limits(cal):
    return {s.channel: (s.min, s.max) for s in cal.servos.values()}


@pytest.fixture(params=PROTOCOLS)
def rig(request, fast_cal):
    """(protocol name, fake controller, pty) for each protocol."""
    fake = FakeController(request.param, limits=_limits(fast_cal))
    with PtyController(fake) as pty:
        yield request.param, fake, pty


def test_every_direction_and_script_through_a_pty_is_checked_byte_by_byte(rig, fast_cal):
    name, fake, pty = rig
    with open_head(pty.port, name, fast_cal, timeout=5.0) as head:
        assert head.feedback is (name != "pms5005")
        for d in ("left", "left_down", "down", "right_down", "right", "centre"):
            head.look(d)
            assert head.wait(timeout=10.0)
            assert head.looking_at() == d
        head.emit("look(down)")
        head.emit("name_object")
        assert head.looking_at() == "down"
    assert fake.violations == []
    assert _settled(fake, head.bytes_written) == head.bytes_written > 0
    final = fake.moves[-1]
    assert set(final.values()) <= {1500}  # closing returned every servo to centre
    for move in fake.moves:
        for ch, pulse in move.items():
            lo, hi = _limits(fast_cal)[ch]
            assert lo <= pulse <= hi


def test_positions_are_read_back_from_the_controller(fast_cal):
    fake = FakeController("maestro", limits=_limits(fast_cal))
    with PtyController(fake) as pty, SerialHead(pty.port, "maestro", fast_cal, timeout=5.0) as head:
        head.move_to({"neck_pan": 1713})
        head.wait(2.0)
        assert head.positions()["neck_pan"] == 1713.0
        assert "position 0" in fake.queries


@pytest.mark.slow
def test_ssc32_reports_moving_then_done(fast_cal):
    fake = FakeController("ssc32", limits=_limits(fast_cal))
    # generous timeouts: the fake answers from a thread, and CI machines are busy
    with PtyController(fake) as pty, SerialHead(pty.port, "ssc32", fast_cal, timeout=5.0) as head:
        head.move_to({"neck_pan": 2000}, speed=250)  # 2 s
        assert head.is_moving() is True
        assert head.wait(10.0)
        assert head.is_moving() is False
        assert head.positions()["neck_pan"] == 2000.0  # QP answers pulse / 10


def test_maestro_errors_appear_in_status(fast_cal):
    fake = FakeController("maestro")
    with PtyController(fake) as pty, SerialHead(pty.port, "maestro", fast_cal, timeout=5.0) as head:
        fake.error_bits = 0b10001
        assert head.status()["errors"] == ["serial signal error", "serial protocol error"]
        assert head.status()["errors"] == []  # reading clears them, as on the real board


@pytest.mark.parametrize("name", ["ssc32", "maestro"])
def test_a_silent_controller_is_a_clear_timeout(fast_cal, name):
    fake = FakeController(name, mute=True)
    with PtyController(fake) as pty:
        with pytest.raises(HeadTimeout, match=f"{name} controller on .* did not answer"):
            SerialHead(pty.port, name, fast_cal, timeout=0.1)  # it asks for positions at once
        fake.mute = False
        # answering: a generous time-out, so a busy machine cannot make the fake look silent
        head = SerialHead(pty.port, name, fast_cal, timeout=5.0)
        fake.mute = True  # the controller goes quiet while in use
        head.link.timeout = head.link.serial.timeout = 0.1
        with pytest.raises(HeadTimeout, match="check power, cable, baud rate"):
            head.is_moving()
        head.close(centre=False)


def test_a_lost_port_raises_port_lost_and_reopen_recovers(tmp_path, fast_cal):
    link = tmp_path / "ttyHEAD"  # like a udev symlink under /dev/serial/by-id
    first = PtyController(FakeController("ssc32"))
    os.symlink(first.port, link)
    head = SerialHead(str(link), "ssc32", fast_cal, timeout=0.2)
    head.look("left")
    first.hang_up()
    with pytest.raises((PortLost, HeadTimeout)) as info:
        for _ in range(3):
            head.look("right")
            head.is_moving()
    assert str(link) in str(info.value)
    second_fake = FakeController("ssc32")
    with PtyController(second_fake) as second:
        os.unlink(link)
        os.symlink(second.port, link)
        head.reopen()
        sent_before = head._bytes_before  # bytes that went to the first controller
        head.look("down")
        assert head.wait(2.0)
        assert head.looking_at() == "down"
        head.close()
        head.close()
        assert _settled(second_fake, head.bytes_written - sent_before) > 0
    assert second_fake.violations == []
    assert second_fake.moves[-1] == {0: 1500, 1: 1500, 2: 1500, 3: 1500, 5: 1500}


def test_missing_device_is_port_unavailable_with_a_hint(fast_cal):
    with pytest.raises(PortUnavailable, match="/dev/ttyNOPE.*give sim for the simulated head"):
        open_head("/dev/ttyNOPE", "ssc32", fast_cal)


def test_loop_url_echoes_bytes_that_decode_cleanly(fast_cal):
    with open_head("loop://", "ssc32", fast_cal) as head:
        assert head.feedback is False  # loop:// only echoes; positions are estimated
        head.look("left")
        head.wait(2.0)
        assert head.looking_at() == "left"
        echoed = head.link.serial.read_all()
    fake = FakeController("ssc32", limits=_limits(fast_cal))
    fake.feed(echoed)
    assert fake.violations == []
    assert fake.moves[-1] == {0: 1900, 1: 1500, 2: 1600, 3: 1500, 5: 1500}


def test_socket_url_reaches_a_controller_over_tcp(fast_cal):
    fake = FakeController("pms5005", limits=_limits(fast_cal))
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]

    def serve():
        conn, _ = server.accept()
        with conn:
            while data := conn.recv(4096):
                fake.feed(data)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    with open_head(f"socket://127.0.0.1:{port}", "pms5005", fast_cal) as head:
        head.emit("look(left)")
        assert head.looking_at() == "left"
    thread.join(timeout=2)
    server.close()
    assert fake.violations == []
    assert fake.moves[1] == {0: 1900, 1: 1500, 2: 1600, 3: 1500, 5: 1500}
