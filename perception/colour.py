"""Colour of the salient area: histogram modes of r, g, b and HSI hue, and a colour name.

Following the paper, the colour of an area is the most frequent value of each of the r, g, b
channels and of the HSI hue over the area's pixels. Hue is undefined for grey pixels, so the hue
histogram only counts pixels whose HSI saturation is at least ``min_saturation``; when fewer than
``min_chromatic`` of the pixels qualify the area has no colour name.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from perception.vocabulary import HUES

__all__ = ["ColourSummary", "colour_name", "colour_summary", "hsi"]

_RGB_BINS = 32
_HUE_BINS = 72


@dataclass(frozen=True)
class ColourSummary:
    """Histogram modes of an area.

    Attributes:
        r, g, b: most frequent channel values (0..255, bin centres).
        hue: most frequent HSI hue in degrees (0..360), ``None`` when the area is grey.
        saturation: median HSI saturation (0..1) of the pixels near the modal hue.
        intensity: median HSI intensity (0..1) of the area.
        name: colour name from :data:`perception.vocabulary.COLOURS`, or ``None``.
    """

    r: int
    g: int
    b: int
    hue: float | None
    saturation: float
    intensity: float
    name: str | None


def hsi(pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """HSI hue (degrees), saturation and intensity of ``(n, 3)`` BGR pixels (0..255)."""
    p = pixels.astype(np.float32) / 255.0
    b, g, r = p[:, 0], p[:, 1], p[:, 2]
    total = r + g + b
    intensity = total / 3.0
    saturation = 1.0 - 3.0 * np.minimum(np.minimum(r, g), b) / np.maximum(total, 1e-6)
    num = 0.5 * ((r - g) + (r - b))
    den = np.sqrt((r - g) ** 2 + (r - b) * (g - b)) + 1e-9
    theta = np.degrees(np.arccos(np.clip(num / den, -1.0, 1.0)))
    hue = np.where(b > g, 360.0 - theta, theta)
    return hue, saturation, intensity


def colour_name(hue: float | None) -> str | None:
    """The name of a hue (degrees) from :data:`perception.vocabulary.HUES`; ``None`` for no hue."""
    if hue is None:
        return None
    h = hue % 360.0
    for name, (lo, hi) in HUES.items():
        if (lo <= h < hi) if lo < hi else (h >= lo or h < hi):
            return name
    return None  # pragma: no cover - the ranges cover the circle


def colour_summary(frame: np.ndarray, mask: np.ndarray, min_saturation: float = 0.2,
                   min_chromatic: float = 0.15) -> ColourSummary:
    """Summarise the colour of the masked area of a BGR frame.

    Args:
        frame: ``(h, w, 3)`` uint8 BGR image.
        mask: ``(h, w)`` mask, non-zero inside the area.
        min_saturation: HSI saturation from which a pixel has a hue.
        min_chromatic: fraction of chromatic pixels needed for a colour name.

    Returns:
        The summary.
    """
    import cv2

    # gathered inside the area's bounding box: the same pixels in the same order, faster
    inside = np.asarray(mask) > 0
    x, y, w, h = cv2.boundingRect(inside.view(np.uint8))
    pixels = frame[y:y + h, x:x + w][inside[y:y + h, x:x + w]]
    if len(pixels) == 0:
        return ColourSummary(0, 0, 0, None, 0.0, 0.0, None)
    step = 256 // _RGB_BINS
    modes = [int(np.argmax(np.bincount(pixels[:, k] // step, minlength=_RGB_BINS))) * step
             + step // 2 for k in (2, 1, 0)]
    hue, sat, inten = hsi(pixels)
    chroma = sat >= min_saturation
    if chroma.mean() < min_chromatic:
        return ColourSummary(*modes, None, float(np.median(sat)), float(np.median(inten)), None)
    width = 360.0 / _HUE_BINS
    hist = np.bincount((hue[chroma] / width).astype(int) % _HUE_BINS, minlength=_HUE_BINS)
    # smooth circularly so a hue on a bin edge is not split in two
    hist = hist + 0.5 * (np.roll(hist, 1) + np.roll(hist, -1))
    mode = (int(np.argmax(hist)) + 0.5) * width
    near = chroma & (np.abs((hue - mode + 180.0) % 360.0 - 180.0) <= 20.0)
    s = float(np.median(sat[near])) if near.any() else float(np.median(sat[chroma]))
    return ColourSummary(*modes, float(mode), s, float(np.median(inten)), colour_name(mode))
