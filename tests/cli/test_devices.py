"""A servo controller that answers garbage is an error (exit 2, one line), never exit 0."""

from __future__ import annotations

import time

import pytest

from head.fake import FakeController, PtyController
from tests.cli.conftest import one_line_exit_2
from tests.head.conftest import FAST_TOML


@pytest.fixture
def fast_path(tmp_path):
    path = tmp_path / "fast.toml"
    path.write_text(FAST_TOML)
    return path


@pytest.mark.parametrize("protocol", ["maestro", "ssc32"])
@pytest.mark.parametrize("action", [["status"], ["look", "left"]])
def test_garbage_answers_are_an_error(capsys, fast_path, protocol, action):
    fake = FakeController(protocol, garbage=True)
    with PtyController(fake) as pty:
        t0 = time.monotonic()
        line = one_line_exit_2(capsys, ["head", "--port", pty.port, "--protocol", protocol,
                                        "--calibration", str(fast_path), "--timeout", "0.3",
                                        *action], pty.port)
        took = time.monotonic() - t0
    assert protocol in line
    assert took < 5, f"took {took:.1f} s to notice"
    assert fake.violations == []  # what the head sent was still well-formed


def test_maestro_error_register_with_undefined_bits_is_garbage():
    from head.errors import ProtocolError
    from head.protocols.maestro import Maestro

    class Link:
        port = "test"

        def __init__(self, answer: bytes) -> None:
            self.answer = answer

        def transact(self, data, size, what):
            return self.answer

    assert Maestro().query_errors(Link(b"\x20\x00")) == ["serial timeout"]
    with pytest.raises(ProtocolError, match="0xf820"):
        Maestro().query_errors(Link(b"\x20\xf8"))
    with pytest.raises(ProtocolError, match="12266"):
        Maestro().query_positions(Link((12266 * 4).to_bytes(2, "little")), [0])
    assert Maestro().query_positions(Link(b"\x00\x00"), [0]) == {0: 0.0}  # channel off


def test_bytes_beyond_the_answer_are_garbage():
    from head.errors import ProtocolError
    from head.serial_head import SerialLink

    class Chatty:
        """A port that answers what was asked and then some."""

        in_waiting = 3

        def __init__(self, *args, **kwargs) -> None:
            pass

        def reset_input_buffer(self) -> None:
            pass

        def write(self, data: bytes) -> int:
            return len(data)

        def flush(self) -> None:
            pass

        def read(self, size: int) -> bytes:
            return bytes(size)

        def close(self) -> None:
            pass

    link = SerialLink("chatty", 9600, 0.1, "maestro", factory=Chatty)
    with pytest.raises(ProtocolError, match="3 bytes more than the 2 asked"):
        link.transact(b"\x90\x00", 2, "position of channel 0")
    Chatty.in_waiting = 0
    assert link.transact(b"\x90\x00", 2, "position of channel 0") == b"\x00\x00"
