"""Itti-Koch visual saliency, written with numpy and OpenCV primitives.

The five stages of the paper (section 3.1), after Itti, Koch and Niebur (1998):

1. **Feature extraction**: intensity ``I = (r+g+b)/3``; broadly tuned colour channels
   ``R, G, B, Y`` (normalised by intensity where the pixel is not dark); orientation.
2. **Linear filtering**: a Gaussian pyramid of each channel, and Gabor filters at 0, 45, 90 and
   135 degrees on the intensity pyramid.
3. **Centre-surround differences** ``|F(c) - F(s)|`` between a fine centre level ``c`` and a
   coarse surround level ``s = c + delta``: intensity, red/green and blue/yellow double
   opponency, orientation.
4. **Normalisation and linear combination**: each map is multiplied by ``(1 - m/M)^2`` (``M``
   its maximum, ``m`` the mean of its other local maxima), which promotes maps with one strong
   peak and, unlike Itti's rescaling to a fixed range, keeps absolute units so a blank wall
   stays non-salient. Maps sum into intensity, colour and orientation conspicuity maps, which
   are normalised again and averaged into the saliency map.
5. **Selection** of the most salient area: the connected region around the peak where saliency
   is at least ``relative`` times the peak; it is kept only when the peak reaches ``threshold``
   and the region covers at least ``min_area`` of the frame.

For speed the frame is first reduced to a working width of 160 pixels (an eighth of the work of
320x240 and the same map for every input size); the saliency map lives at pyramid level 2 of
that (40x30 for a 4:3 frame).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SaliencyParams", "SalientArea", "most_salient", "saliency_map"]

_CENTRES = (1, 2, 3)
_DELTAS = (2, 3)
_MAP_LEVEL = 2


@dataclass(frozen=True)
class SaliencyParams:
    """Parameters of the saliency stage.

    Attributes:
        work_width: frames are resized to this width before the pyramid.
        threshold: minimum peak saliency (intensity units, 0..1) for a salient area.
        relative: the area is where saliency >= ``relative * peak``.
        min_area: minimum area as a fraction of the frame.
    """

    work_width: int = 160
    threshold: float = 0.08
    relative: float = 0.5
    min_area: float = 0.004


@dataclass(frozen=True)
class SalientArea:
    """The most salient area of a frame, in frame pixels.

    Attributes:
        box: ``(x, y, w, h)`` bounding box.
        mask: uint8 mask of the area, the size of the frame (255 inside).
        peak: saliency at the peak.
        centre: ``(x, y)`` of the peak.
        area: fraction of the frame covered.
    """

    box: tuple[int, int, int, int]
    mask: np.ndarray
    peak: float
    centre: tuple[int, int]
    area: float


def _pyramid(img: np.ndarray, levels: int) -> list[np.ndarray]:
    import cv2

    pyr = [img]
    for _ in range(levels - 1):
        pyr.append(cv2.pyrDown(pyr[-1]))
    return pyr


def _gabor_kernels() -> list[np.ndarray]:
    import cv2

    return [cv2.getGaborKernel((7, 7), 1.6, np.radians(t), 4.0, 1.0, 0.0).astype(np.float32)
            for t in (0, 45, 90, 135)]


_GABORS: list[np.ndarray] = []
_PEAK_KERNEL = np.ones((3, 3), np.uint8)


def _normalise(m: np.ndarray) -> np.ndarray:
    """Itti's N(.): scale a map by ``(1 - mean of other local maxima / max)^2``."""
    import cv2

    top = float(m.max())
    if top <= 1e-9:
        return m
    peaks = (m == cv2.dilate(m, _PEAK_KERNEL)) & (m > 0.05 * top)
    values = m[peaks]
    others = values[values < top]
    # the float32 sum over the count is what ndarray.mean computes, without its overhead
    mean = float(others.sum() / others.size) if others.size else 0.0
    return m * (1.0 - mean / top) ** 2


def _centre_surround(pyr: list[np.ndarray | None], size: tuple[int, int]) -> np.ndarray:
    """Sum over (c, s) of N(|F(c) - F(s)|), each resized to the map level."""
    import cv2

    total = np.zeros(size[::-1], np.float32)
    for c in _CENTRES:
        for d in _DELTAS:
            s = min(c + d, len(pyr) - 1)
            surround = cv2.resize(pyr[s], pyr[c].shape[1::-1], interpolation=cv2.INTER_LINEAR)
            diff = cv2.absdiff(pyr[c], surround)
            total += _normalise(cv2.resize(diff, size, interpolation=cv2.INTER_AREA))
    return total


def saliency_map(frame: np.ndarray, params: SaliencyParams = SaliencyParams()) -> np.ndarray:
    """The saliency map of a BGR frame (float32, at the map level; values in intensity units).

    Args:
        frame: ``(h, w, 3)`` uint8 BGR image.
        params: saliency parameters.

    Returns:
        The saliency map, ``(h', w')`` float32 with ``w' = work_width / 4``.
    """
    import cv2

    if not _GABORS:  # one slice assignment: two threads arriving here make the same list
        _GABORS[:] = _gabor_kernels()
    h, w = frame.shape[:2]
    ww = int(params.work_width)
    wh = max(8, round(h * ww / w))
    small = cv2.resize(frame, (ww, wh), interpolation=cv2.INTER_AREA).astype(np.float32) / 255.0
    b, g, r = cv2.split(small)
    intensity = (r + g + b) / 3.0
    # colour channels, normalised by intensity where it is above a tenth of the maximum
    norm = np.where(intensity > 0.1 * max(float(intensity.max()), 1e-6),
                    1.0 / np.maximum(intensity, 1e-6), 0.0).astype(np.float32) * 0.33
    red = np.maximum(r - (g + b) / 2, 0) * norm
    green = np.maximum(g - (r + b) / 2, 0) * norm
    blue = np.maximum(b - (r + g) / 2, 0) * norm
    yellow = np.maximum((r + g) / 2 - np.abs(r - g) / 2 - b, 0) * norm
    levels = max(_CENTRES) + max(_DELTAS) + 1
    size = (max(1, ww >> _MAP_LEVEL), max(1, wh >> _MAP_LEVEL))
    ipyr = _pyramid(intensity, levels)
    cons_i = _centre_surround(ipyr, size)
    rg = _pyramid(red - green, levels)
    by = _pyramid(blue - yellow, levels)
    cons_c = _centre_surround(rg, size) + _centre_surround(by, size)
    cons_o = np.zeros_like(cons_i)
    for kernel in _GABORS:
        # level 0 is only the base of the pyramid: centre-surround starts at level 1
        opyr = [None] + [np.abs(cv2.filter2D(level, -1, kernel)) for level in ipyr[1:]]
        cons_o += _normalise(_centre_surround(opyr, size))
    return ((_normalise(cons_i) + _normalise(cons_c) + _normalise(cons_o)) / 3.0).astype(
        np.float32)


def most_salient(frame: np.ndarray, params: SaliencyParams = SaliencyParams(),
                 exclude: list[tuple[int, int, int, int]] | None = None,
                 smap: np.ndarray | None = None) -> SalientArea | None:
    """Select the most salient area of a frame.

    Args:
        frame: BGR frame.
        params: saliency parameters.
        exclude: frame boxes ``(x, y, w, h)`` to ignore (for example detected faces).
        smap: a saliency map already computed for this frame.

    Returns:
        The area, or ``None`` when nothing passes the threshold and the minimum area.
    """
    import cv2

    s = saliency_map(frame, params) if smap is None else smap.copy()
    h, w = frame.shape[:2]
    mh, mw = s.shape
    fx, fy = mw / w, mh / h
    for x, y, bw, bh in exclude or []:
        x0, y0 = int(x * fx), int(y * fy)
        x1, y1 = int(np.ceil((x + bw) * fx)), int(np.ceil((y + bh) * fy))
        s[max(0, y0 - 1):y1 + 1, max(0, x0 - 1):x1 + 1] = 0.0
    peak = float(s.max())
    if peak < params.threshold:
        return None
    py, px = np.unravel_index(int(np.argmax(s)), s.shape)
    above = (s >= params.relative * peak).astype(np.uint8)
    _, labels = cv2.connectedComponents(above, connectivity=8)
    small = (labels == labels[py, px]).astype(np.uint8) * 255
    mask = cv2.resize(small, (w, h), interpolation=cv2.INTER_LINEAR)
    cv2.threshold(mask, 127, 255, cv2.THRESH_BINARY, dst=mask)  # 255 where >= 128, else 0
    area = float(np.count_nonzero(mask)) / (w * h)
    if area < params.min_area:
        return None
    x, y, bw, bh = cv2.boundingRect(mask)
    centre = (int((px + 0.5) / fx), int((py + 0.5) / fy))
    return SalientArea((x, y, bw, bh), mask, peak, centre, area)
