"""Protocol encoders: exact bytes, registry, last-line guards."""

from __future__ import annotations

import pytest

from head.errors import HeadError, UnknownProtocol
from head.fake import FakeController, crc8_maxim_reflected
from head.protocols import PROTOCOLS, Command, check_command, get_protocol
from head.protocols.pms5005 import crc8_maxim, packet, pulse_to_value


def test_registry_names_and_suggestions():
    assert sorted(PROTOCOLS) == ["maestro", "pms5005", "ssc32"]
    for name in PROTOCOLS:
        assert get_protocol(name).name == name
    with pytest.raises(UnknownProtocol, match="did you mean 'pms5005'"):
        get_protocol("pms5050")


def test_ssc32_group_move_bytes():
    data = get_protocol("ssc32").encode_move(
        [Command(0, 1500, 600.0), Command(3, 1750, 1200.4)], 400)
    assert data == b"#0P1500S600#3P1750S1200\r"


def test_maestro_speed_and_target_bytes():
    data = get_protocol("maestro").encode_move([Command(2, 1500, 600.0)], 0)
    # speed 600 us/s = 24 units of 25 us/s; target 6000 quarter-us = 0x70 0x2E in 7-bit halves
    assert data == bytes([0x87, 2, 24, 0, 0x84, 2, 6000 & 0x7F, 6000 >> 7])


def test_maestro_never_sends_speed_zero_which_means_unlimited():
    data = get_protocol("maestro").encode_move([Command(0, 1500, 1.0)], 0)
    assert data[:4] == bytes([0x87, 0, 1, 0])


def test_maestro_setup_sets_acceleration_only_where_declared():
    assert get_protocol("maestro").setup([(0, 0), (1, 4)]) == bytes([0x89, 1, 4, 0])


def test_crc8_maxim_check_value_and_two_independent_implementations_agree():
    assert crc8_maxim(b"123456789") == 0xA1
    for data in (b"", b"\x00", b"\x01\x00\x1d\x0e" + bytes(range(14)), bytes(range(256))):
        assert crc8_maxim(data) == crc8_maxim_reflected(data)


def test_pms5005_packet_layout():
    data = get_protocol("pms5005").encode_move([Command(1, 1500, 500.0)], 300)
    assert data[:6] == bytes([0x5E, 0x02, 0x01, 0x00, 29, 14])
    assert data[-2:] == bytes([0x5E, 0x0D])
    values = [int.from_bytes(data[6 + 2 * i:8 + 2 * i], "little") for i in range(6)]
    assert values == [0x8000, 3375, 0x8000, 0x8000, 0x8000, 0x8000]  # 1.5 ms x 2250
    assert int.from_bytes(data[18:20], "little") == 300
    assert data[20] == crc8_maxim(data[2:20])
    assert pulse_to_value(1000) == 2250
    assert packet(1, b"") == bytes([0x5E, 0x02, 0x01, 0x00, 0x01, 0x00,
                                    crc8_maxim(b"\x01\x00\x01\x00"), 0x5E, 0x0D])


@pytest.mark.parametrize("name", sorted(PROTOCOLS))
def test_encoders_refuse_out_of_range_commands(name):
    proto = get_protocol(name)
    for bad in (Command(0, 499, 100.0), Command(0, 2501, 100.0), Command(0, 1500, 0.0),
                Command(proto.max_channel + 1, 1500, 100.0)):
        with pytest.raises(HeadError, match="refusing|does not exist"):
            proto.encode_move([bad], 100)
    check_command(Command(0, 500, 1.0), proto.max_channel)


@pytest.mark.parametrize("name", sorted(PROTOCOLS))
def test_fake_decoder_reads_back_what_the_encoder_wrote(name):
    proto = get_protocol(name)
    fake = FakeController(name, clock=lambda: 0.0)
    cmds = [Command(0, 1234, 800.0), Command(1, 1777, 800.0), Command(5, 2000, 800.0)]
    fake.feed(proto.setup([(0, 3)]) + proto.encode_move(cmds, 500))
    merged = {}
    for move in fake.moves:
        merged.update(move)
    assert merged == {0: 1234, 1: 1777, 5: 2000}
    assert fake.violations == []


@pytest.mark.parametrize(("name", "data", "problem"), [
    ("ssc32", b"#0P1500X\r", "not allowed"),
    ("ssc32", b"#0P15\r", "cannot parse"),
    ("maestro", b"\x84\x00\x80\x00", "top bit"),
    ("maestro", b"\x42", "unknown command"),
    ("pms5005", b"\x5e\x03", "expected 0x02"),
    ("pms5005", packet(29, bytes(14))[:-3] + b"\x00\x5e\x0d", "CRC"),
    ("pms5005", packet(29, bytes(14))[:-1] + b"\x0a", "ETX1"),
    ("pms5005", packet(7, b"\x01"), "unsupported"),
])
def test_fake_controller_rejects_bad_bytes(name, data, problem):
    fake = FakeController(name)
    fake.feed(data)
    assert any(problem in v for v in fake.violations), fake.violations


def test_fake_controller_flags_pulses_outside_its_limits():
    fake = FakeController("ssc32", limits={0: (1000, 2000)})
    fake.feed(b"#0P2100S100\r")
    assert fake.violations == ["ssc32: channel 0 pulse 2100 us outside 1000..2000"]


def test_a_protocol_without_feedback_says_so_when_asked_for_it() -> None:
    proto = get_protocol("pms5005")
    assert not proto.feedback
    with pytest.raises(HeadError, match="pms5005 protocol cannot report motion"):
        proto.query_moving(None, {0: 1500})  # type: ignore[arg-type]
    with pytest.raises(HeadError, match="cannot report positions"):
        proto.query_positions(None, [0])  # type: ignore[arg-type]
