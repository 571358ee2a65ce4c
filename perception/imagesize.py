"""Image sizes read from file headers, and the frame sizes perception accepts.

A 124-byte PNG can claim to be 100000 x 100000 pixels, and a 1 x 10000 one makes every
stage that scales frames to a working width allocate gigabytes. So the size is read from the
file's header *before* anything is decoded (:func:`header_size`) and checked against
:data:`LIMITS` (:func:`check_frame_size`); frames from cameras and videos are checked the
same way before they are analysed.

Formats read: PNG, JPEG, BMP, GIF, WebP, TIFF, and the PNM family (PBM/PGM/PPM/PAM). A file
in any other format is refused rather than handed to a decoder whose memory use is unknown.
"""

from __future__ import annotations

import io
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from perception.errors import ImageError

__all__ = ["FORMATS", "LIMITS", "FrameLimits", "check_frame_size", "header_size",
           "header_size_of"]

#: the formats :func:`header_size` reads.
FORMATS = ("PNG", "JPEG", "BMP", "GIF", "WebP", "TIFF", "PNM")


@dataclass(frozen=True)
class FrameLimits:
    """The frame sizes perception accepts.

    Attributes:
        min_side: pixels on the shorter side (the pipeline's pyramids need some).
        max_side: pixels on the longer side.
        max_pixels: width x height (50 megapixels: 150 MB as a BGR frame).
        max_ratio: longer side / shorter side (8:1 admits every camera and panorama).
    """

    min_side: int = 16
    max_side: int = 16384
    max_pixels: int = 50_000_000
    max_ratio: float = 8.0


LIMITS = FrameLimits()


def check_frame_size(width: int, height: int, what: str,
                     limits: FrameLimits = LIMITS) -> None:
    """Refuse a frame size perception cannot handle in bounded time and memory.

    Args:
        width, height: pixels.
        what: names the image or source in the message.
        limits: the bounds.

    Raises:
        ImageError: one line naming ``what`` and the size ``WxH``.
    """
    size = f"{width}x{height}"
    short, long_ = min(width, height), max(width, height)
    if short < limits.min_side:
        problem = f"needs at least {limits.min_side} pixels on each side"
    elif long_ > limits.max_side:
        problem = f"allows at most {limits.max_side} pixels on a side"
    elif width * height > limits.max_pixels:
        problem = f"allows at most {limits.max_pixels / 1e6:g} megapixels"
    elif long_ / short > limits.max_ratio:
        problem = f"allows sides in a ratio up to {limits.max_ratio:g}:1"
    else:
        return
    raise ImageError(f"{what} is {size} pixels; perception {problem} (scale it first)")


# ---- headers -------------------------------------------------------------------------------

def _png(fh: BinaryIO, head: bytes) -> tuple[int, int]:
    if head[12:16] != b"IHDR":
        raise ValueError("no IHDR chunk")
    return struct.unpack(">II", head[16:24])


_SOF = {0xC0, 0xC1, 0xC2, 0xC3, 0xC5, 0xC6, 0xC7, 0xC9, 0xCA, 0xCB, 0xCD, 0xCE, 0xCF}


def _jpeg(fh: BinaryIO, head: bytes) -> tuple[int, int]:
    fh.seek(2)
    while True:
        byte = fh.read(1)
        if not byte:
            raise ValueError("no frame header before the end")
        if byte != b"\xff":
            continue
        marker = fh.read(1)
        while marker == b"\xff":  # fill bytes
            marker = fh.read(1)
        if not marker:
            raise ValueError("no frame header before the end")
        code = marker[0]
        if code == 0xD8 or 0xD0 <= code <= 0xD7 or code == 0x01:
            continue  # markers without a length
        if code == 0xDA:
            raise ValueError("image data before a frame header")
        length = struct.unpack(">H", fh.read(2))[0]
        if length < 2:
            raise ValueError(f"segment length {length}")
        if code in _SOF:
            _, height, width = struct.unpack(">BHH", fh.read(5))
            return width, height
        fh.seek(length - 2, 1)


def _bmp(fh: BinaryIO, head: bytes) -> tuple[int, int]:
    (dib,) = struct.unpack("<I", head[14:18])
    if dib == 12:
        return struct.unpack("<HH", head[18:22])
    width, height = struct.unpack("<ii", head[18:26])
    return abs(width), abs(height)


def _gif(fh: BinaryIO, head: bytes) -> tuple[int, int]:
    return struct.unpack("<HH", head[6:10])


def _webp(fh: BinaryIO, head: bytes) -> tuple[int, int]:
    kind = head[12:16]
    if kind == b"VP8 ":
        w, h = struct.unpack("<HH", head[26:30])
        return w & 0x3FFF, h & 0x3FFF
    if kind == b"VP8L":
        bits = int.from_bytes(head[21:25], "little")
        return (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1
    if kind == b"VP8X":
        return (int.from_bytes(head[24:27], "little") + 1,
                int.from_bytes(head[27:30], "little") + 1)
    raise ValueError(f"unknown WebP chunk {kind!r}")


def _tiff(fh: BinaryIO, head: bytes) -> tuple[int, int]:
    order = "<" if head[:2] == b"II" else ">"
    (offset,) = struct.unpack(order + "I", head[4:8])
    fh.seek(offset)
    (count,) = struct.unpack(order + "H", fh.read(2))
    found: dict[int, int] = {}
    for _ in range(min(count, 4096)):
        tag, kind, _n, value = struct.unpack(order + "HHI4s", fh.read(12))
        if tag in (256, 257):
            fmt = order + ("H" if kind == 3 else "I")
            found[tag] = struct.unpack(fmt, value[:struct.calcsize(fmt)])[0]
    if 256 not in found or 257 not in found:
        raise ValueError("no width or height tag")
    return found[256], found[257]


def _pnm(fh: BinaryIO, head: bytes) -> tuple[int, int]:
    if head[:2] == b"P7":  # PAM: WIDTH and HEIGHT lines
        fields = dict(line.split(None, 1) for line in head.decode("ascii", "replace")
                      .splitlines()[1:] if " " in line)
        return int(fields["WIDTH"]), int(fields["HEIGHT"])
    tokens: list[bytes] = []
    for line in head[2:].splitlines():
        tokens += line.split(b"#", 1)[0].split()
        if len(tokens) >= 2:
            return int(tokens[0]), int(tokens[1])
    raise ValueError("no width and height")


_MAGIC = [
    (b"\x89PNG\r\n\x1a\n", "PNG", _png),
    (b"\xff\xd8", "JPEG", _jpeg),
    (b"BM", "BMP", _bmp),
    (b"GIF87a", "GIF", _gif),
    (b"GIF89a", "GIF", _gif),
    (b"II*\x00", "TIFF", _tiff),
    (b"MM\x00*", "TIFF", _tiff),
] + [(f"P{i}".encode(), "PNM", _pnm) for i in range(1, 8)]


def header_size(path: str | Path) -> tuple[int, int, str]:
    """The ``(width, height, format)`` an image file's header declares, without decoding.

    Raises:
        ImageError: the file cannot be read, is in a format not in :data:`FORMATS`, or its
            header is cut short or inconsistent.
    """
    try:
        with open(Path(path), "rb") as fh:
            return _read_header(fh, repr(str(path)))
    except OSError as exc:
        raise ImageError(f"cannot read {str(path)!r}: {exc.strerror or exc}") from None


def header_size_of(data: bytes, what: str) -> tuple[int, int, str]:
    """The ``(width, height, format)`` the header of an image held in memory declares (a
    compressed frame in a bag or a recording), without decoding it.

    Args:
        data: the encoded image (PNG, JPEG, ...).
        what: names the image in the message.

    Raises:
        ImageError: a format not in :data:`FORMATS`, or a header cut short or inconsistent.
    """
    return _read_header(io.BytesIO(data), what)


def _read_header(fh: BinaryIO, what: str) -> tuple[int, int, str]:
    head = fh.read(512)
    if head[:4] == b"RIFF" and head[8:12] == b"WEBP":
        found = [("WebP", _webp)]
    else:
        found = [(name, f) for magic, name, f in _MAGIC if head.startswith(magic)]
    if not found:
        raise ImageError(f"cannot decode {what}: not an image in a format perception reads "
                         f"({', '.join(FORMATS)})")
    name, reader = found[0]
    try:
        width, height = reader(fh, head)
    except (ValueError, KeyError, IndexError, struct.error) as exc:
        raise ImageError(f"cannot decode {what}: damaged {name} header "
                         f"({exc or 'cut short'})") from None
    return int(width), int(height), name
