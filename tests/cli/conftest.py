"""The bad-input and fault corpus: shared files and the one-line-exit-2 check."""

from __future__ import annotations

import random
import struct
import zlib
from pathlib import Path

import pytest

from relrl.cli import main

ROOT = Path(__file__).resolve().parents[2]
FRUITS = ROOT / "examples" / "domains" / "fruits.pl"


def episode_text(body: str = "", *, steps: int = 6, head: str = "") -> str:
    """A small symbolic episode on the fruits domain (``head`` goes into [episode])."""
    return (f'[episode]\ndomain = "{FRUITS}"\nseed = 1\n{head}\n[world]\n'
            f'perception = "symbolic"\n[[phase]]\nsteps = {steps}\ncaregiver = "script"\n'
            + body)


def _chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def png_bytes(width: int, height: int, pixels: bytes | None = None) -> bytes:
    """A PNG whose header says ``width`` x ``height`` (RGB); ``pixels`` default: all black."""
    if pixels is None:
        pixels = b"".join(b"\x00" + bytes(3 * width) for _ in range(height))
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr)
            + _chunk(b"IDAT", zlib.compress(pixels, 9)) + _chunk(b"IEND", b""))


def jpeg_header(width: int, height: int) -> bytes:
    """The start of a baseline JPEG whose frame header says ``width`` x ``height``."""
    sof = b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, height, width, 1) + b"\x01\x11\x00"
    return b"\xff\xd8" + b"\xff\xe0" + struct.pack(">H", 16) + b"JFIF\x00\x01\x01\x00" \
        + b"\x00\x01\x00\x01\x00\x00" + sof + b"\xff\xd9"


def _mcap_start() -> bytes:
    """The first bytes an MCAP writer writes (magic and header record)."""
    import io

    from mcap.writer import Writer

    buf = io.BytesIO()
    Writer(buf).start(profile="", library="relrl")
    return buf.getvalue()


@pytest.fixture(scope="session")
def corpus(tmp_path_factory) -> Path:
    """A folder of hostile inputs shared by the corpus tests."""
    d = tmp_path_factory.mktemp("corpus")
    rng = random.Random(14)
    noise = bytes(rng.randrange(256) for _ in range(2048))
    (d / "afile").write_text("not a folder\n")
    (d / "adir").mkdir()
    (d / "random.bin").write_bytes(noise)
    (d / "latin1.pl").write_bytes("stimulus(caf\xe9).\n".encode("latin-1"))
    (d / "random.toml").write_bytes(noise)
    (d / "latin1.toml").write_bytes('[episode]\nname = "caf\xe9"\n'.encode("latin-1"))
    (d / "empty.toml").write_text("")
    (d / "huge.png").write_bytes(png_bytes(100000, 100000, b"\x00" * 1000))
    (d / "tall.png").write_bytes(png_bytes(1, 10000))
    (d / "huge.jpg").write_bytes(jpeg_header(60000, 60000))
    (d / "truncated.png").write_bytes(png_bytes(64, 48)[:40])
    (d / "text.png").write_text("this is not an image\n")
    (d / "calibration.bin").write_bytes(noise)
    (d / "junk.mcap").write_bytes(noise)
    (d / "cut.mcap").write_bytes(_mcap_start()[:30])  # a recording cut in its header
    eps = {
        "ok.toml": episode_text(),
        "negative_seed.toml": episode_text().replace("seed = 1", "seed = -1"),
        "traversal.toml": episode_text(head='policy_save = "../../escaped-policy.pl"'),
        "absolute.toml": episode_text(head=f'policy_save = "{d}/abs-policy.pl"'),
        "reserved.toml": episode_text(head='policy_save = "summary.json"'),
        "dir_policy.toml": episode_text(head='policy_save = "policies/"'),
    }
    for name, text in eps.items():
        (d / name).write_text(text)
    return d


def one_line_exit_2(capsys, argv: list[str], *needles: str) -> str:
    """Run ``relrl ARGV`` in this process; it must print one line naming ``needles`` and
    return 2 (an exception escaping ``main`` fails the test with its traceback)."""
    code = main(argv)
    captured = capsys.readouterr()
    err = captured.err
    assert code == 2, f"exit {code}, stderr: {err!r}"
    assert "Traceback" not in err, err
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1, f"expected one line, got {lines!r}"
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    return lines[0]
