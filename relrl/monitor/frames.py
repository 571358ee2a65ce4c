"""Camera frames as JPEG: encoding for the browser and the recording, decoding for replay."""

from __future__ import annotations

from typing import Any

__all__ = ["decode_jpeg", "encode_jpeg"]


def encode_jpeg(frame: Any, quality: int = 80) -> bytes:
    """A BGR frame as JPEG bytes (OpenCV; ``quality`` 1..100)."""
    import cv2

    ok, buf = cv2.imencode(".jpg", frame, [int(cv2.IMWRITE_JPEG_QUALITY), int(quality)])
    if not ok:  # pragma: no cover - OpenCV encodes any uint8 BGR image
        raise ValueError("OpenCV could not encode the frame as JPEG")
    return buf.tobytes()


def decode_jpeg(data: bytes) -> Any:
    """JPEG bytes back to a BGR frame (``None`` when they are not an image)."""
    import cv2
    import numpy as np

    return cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
