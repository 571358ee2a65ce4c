"""A compiled evaluator of OpenCV's Haar cascades: OpenCV's detections, 2.1-3.2 times faster.

:class:`Cascade` reads a cascade file shipped in the OpenCV wheel (stumps or two-node trees,
upright Haar features: the frontal ``alt2`` and the profile face cascades) and searches an image
for it exactly as ``cv2.CascadeClassifier.detectMultiScale`` of OpenCV 4 does, with
:func:`numba.njit` kernels:

* the same scales (``factor *= scale_factor`` from 1 while the window fits ``max_size`` and the
  image, from ``min_size`` up; when no step's window lies in ``[min_size, max_size]``, the one
  nearest ``min_size``), the same scaled images (``cv2.resize`` with ``INTER_LINEAR_EXACT`` to
  ``round(w / scale)``) and their integral images;
* the same windows: every 2 pixels of the scaled image below scale 2, every pixel from 2 up, the
  next window skipped after one the first stage rejects, the rows past OpenCV's last full stripe
  left out; windows whose grey-level standard deviation over the inner ``(w-2) x (h-2)`` pixels
  is 10 or less are rejected, as OpenCV 4 does;
* the same arithmetic: integer rectangle sums, each feature ``w0 * float(r0) + w1 * float(r1)
  [+ w2 * float(r2)]`` in single precision times the window's single-precision ``1 / (area *
  std)``, stage sums of single-precision leaves accumulated in double precision against the
  stage threshold less ``1e-5``;
* the same grouping (``cv2.groupRectangles(hits, min_neighbors, 0.2)``) and clipping to the
  image.

The raw hits are the same set as OpenCV's (``min_neighbors=0``; OpenCV's order among them
depends on its stripes), the grouped faces the same boxes (checked on 16,704 searches; the
tests check both on every run). The speed comes from the order of work: OpenCV runs the cascade
window by window; here each stage runs over all the windows still alive at one scale, one weak
classifier at a time (its feature offsets stay in registers, the loop has no branches), and the
windows that pass are compacted before the next stage. Unsigned indices keep numba from adding
negative-index checks to every integral-image read. The kernels release the GIL, so threads
search at once.

Without numba the same calls run OpenCV's own ``detectMultiScale`` (same faces, slower).
"""

from __future__ import annotations

import threading
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Cascade", "CascadeModel", "group", "parse_cascade"]

#: OpenCV lowers every stage threshold by this much (``THRESHOLD_EPS``).
_THRESHOLD_EPS = np.float32(1e-5)


@dataclass(frozen=True)
class CascadeModel:
    """The contents of a Haar cascade file, as parsed (double precision, as written).

    Attributes:
        width, height: the detection window.
        rects: ``(features, 3, 4)`` int rectangles ``x, y, w, h`` (unused ones all zero).
        weights: ``(features, 3)`` rectangle weights (0 for an unused rectangle).
        stage_threshold: ``(stages,)`` thresholds of the stage sums.
        stage_first, stage_count: each stage's first weak classifier and their number.
        weak: ``(weaks, 3)`` rows ``node count, first node, first leaf``.
        nodes: ``(nodes, 3)`` rows ``left, right, feature`` (a child ``<= 0`` is leaf ``-child``
            of the weak classifier).
        node_threshold: ``(nodes,)`` feature thresholds.
        leaves: ``(leaves,)`` leaf values.
    """

    width: int
    height: int
    rects: np.ndarray
    weights: np.ndarray
    stage_threshold: np.ndarray
    stage_first: np.ndarray
    stage_count: np.ndarray
    weak: np.ndarray
    nodes: np.ndarray
    node_threshold: np.ndarray
    leaves: np.ndarray


def parse_cascade(path: str | Path) -> CascadeModel:
    """Read an OpenCV (new format) Haar cascade file.

    Raises:
        ValueError: for a file this evaluator cannot run the way OpenCV does (not a boosted
            Haar cascade, tilted features, trees other than stumps and two-node chains).
    """
    root = ET.parse(str(path)).getroot()[0]
    if root.findtext("stageType", "").strip() != "BOOST" \
            or root.findtext("featureType", "").strip() != "HAAR":
        raise ValueError(f"{path}: not a boosted Haar cascade")
    rects, weights = [], []
    for feature in root.find("features"):
        if int(feature.findtext("tilted", "0")) != 0:
            raise ValueError(f"{path}: tilted features are not supported")
        rows = [[float(v) for v in r.text.split()] for r in feature.find("rects")]
        rows += [[0.0] * 5] * (3 - len(rows))
        rects.append([row[:4] for row in rows])
        weights.append([row[4] for row in rows])
    thresholds, first, count, weak, nodes, node_thr, leaves = [], [], [], [], [], [], []
    for stage in root.find("stages"):
        thresholds.append(float(stage.findtext("stageThreshold")))
        first.append(len(weak))
        classifiers = list(stage.find("weakClassifiers"))
        count.append(len(classifiers))
        for classifier in classifiers:
            values = classifier.findtext("internalNodes").split()
            n = len(values) // 4
            weak.append((n, len(nodes), len(leaves)))
            for k in range(n):
                left, right, feature, threshold = values[4 * k:4 * k + 4]
                nodes.append((int(left), int(right), int(feature)))
                node_thr.append(float(threshold))
            leaves += [float(v) for v in classifier.findtext("leafValues").split()]
            if n == 2 and not (nodes[-2][:2] in ((0, 1), (1, 0)) and nodes[-1][:2] == (-1, -2)):
                raise ValueError(f"{path}: only stumps and two-node trees are supported")
            if n > 2:
                raise ValueError(f"{path}: only stumps and two-node trees are supported")
    return CascadeModel(int(root.findtext("width")), int(root.findtext("height")),
                        np.array(rects, np.int32).reshape(-1, 3, 4),
                        np.array(weights, np.float64).reshape(-1, 3),
                        np.array(thresholds), np.array(first, np.int32),
                        np.array(count, np.int32), np.array(weak, np.int32).reshape(-1, 3),
                        np.array(nodes, np.int32).reshape(-1, 3), np.array(node_thr),
                        np.array(leaves))


def _scales(width: int, height: int, win: tuple[int, int], scale_factor: float, min_size: int,
            max_size: int) -> list[np.float32]:
    """The scales OpenCV 4 searches, as single floats: ``factor *= scale_factor`` from 1, those
    whose window lies in ``[min_size, max_size]``; when none does (``min_size == max_size`` not
    on a step, or a range between two steps), the one whose window is nearest ``min_size``
    (ties to the smaller). Windows larger than the image are never searched."""
    fits, factor = [], 1.0
    while True:
        ww, wh = round(win[0] * factor), round(win[1] * factor)
        if ww > width or wh > height:
            break
        fits.append((ww, wh, factor))
        factor *= scale_factor
    inside = []
    for ww, wh, f in fits:
        if ww > max_size or wh > max_size:
            break
        if ww >= min_size and wh >= min_size:
            inside.append(np.float32(f))
    if inside or not fits:
        return inside
    return [np.float32(min(fits, key=lambda t: abs(t[0] - min_size))[2])]


_KERNELS: dict[str, object] = {}
_KERNELS_LOCK = threading.Lock()


def _kernels():
    """The numba kernels (compiled on first use, cached on disk), or ``None`` without numba."""
    with _KERNELS_LOCK:
        if "search" not in _KERNELS:
            try:
                from perception import _cascade_kernels as k
            except ImportError:  # pragma: no cover - numba is a dependency
                _KERNELS["search"] = None
            else:
                _KERNELS["search"], _KERNELS["offsets"] = k.search, k.offsets
        return _KERNELS["search"]


class Cascade:
    """A Haar cascade that searches like ``cv2.CascadeClassifier``, compiled with numba.

    Args:
        path: the cascade file, e.g. ``cv2.data.haarcascades + "haarcascade_profileface.xml"``.

    One object may be used by several threads at once.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        m = parse_cascade(path)
        self.model = m
        self.window = (m.width, m.height)
        # the single-precision values OpenCV keeps
        self._rects = m.rects
        self._weights = m.weights.astype(np.float32)
        self._stage_thr = m.stage_threshold.astype(np.float32) - _THRESHOLD_EPS
        self._node_thr = m.node_threshold.astype(np.float32)
        self._leaves = m.leaves.astype(np.float32)
        self._offsets: dict[int, np.ndarray] = {}
        self._opencv = None

    def raw(self, grey: np.ndarray, scale_factor: float, min_size: int, max_size: int,
            band: tuple[int, int] | None = None) -> list[list[int]]:
        """Every window the cascade accepts, ``[x, y, w, h]`` in ``grey`` (not clipped).

        Args:
            grey: ``(h, w)`` uint8 image.
            scale_factor: scale step (> 1).
            min_size, max_size: window sides searched, in image pixels.
            band: only the scales of this search whose window side is in ``[lo, hi]`` (a
                part of the search to run in another thread; the parts' hits together are
                the whole search's).

        Returns:
            The raw hits by scale, then row, then column: OpenCV's set of raw hits.

        Raises:
            ValueError: for an image that is not 2-D uint8, or a scale step not above 1.
        """
        import cv2

        _check(grey, scale_factor)
        search = _kernels()
        h, w = grey.shape
        scales = _scales(w, h, self.window, scale_factor, min_size, max_size)
        if search is None:
            return self._opencv_hits(grey, scale_factor, 0, min_size, max_size, scales, band)
        if not scales:
            return []
        sizes = [(int(np.rint(np.float32(w) / s)), int(np.rint(np.float32(h) / s)))
                 for s in scales]
        # OpenCV cuts each scale's rows into as many stripes as the first scale has 32-pixel
        # columns, of whole window steps: rows past the last full stripe are not searched
        stripes = -(-(sizes[0][0] + 1 - self.window[0]) // 32)
        if band is not None:
            keep = [k for k, s in enumerate(scales)
                    if band[0] <= int(np.rint(np.float32(self.window[0]) * s)) <= band[1]]
            scales, sizes = [scales[k] for k in keep], [sizes[k] for k in keep]
            if not scales:
                return []
        stride = max(sw for sw, _ in sizes) + 1
        sums = np.zeros((sum(sh + 1 for _, sh in sizes), stride), np.int32)
        squares = np.zeros_like(sums)
        layers = np.zeros((len(scales), 5), np.int32)
        row = 0
        for k, (s, (sw, sh)) in enumerate(zip(scales, sizes, strict=True)):
            img = grey if (sw, sh) == (w, h) else cv2.resize(
                grey, (sw, sh), interpolation=cv2.INTER_LINEAR_EXACT)
            s1, s2 = cv2.integral2(img, sdepth=cv2.CV_32S, sqdepth=cv2.CV_32S)
            sums[row:row + sh + 1, :sw + 1] = s1
            squares[row:row + sh + 1, :sw + 1] = s2
            step = 1 if s >= 2 else 2
            rows = max(sh + 1 - self.window[1], 0)
            stripe = max((rows // step + stripes - 1) // stripes, 1) * step
            layers[k] = (row, sw, sh, step, min(stripes * stripe, rows))
            row += sh + 1
        offsets = self._offsets.get(stride)
        if offsets is None:
            offsets = self._offsets[stride] = _KERNELS["offsets"](self._rects, stride)
        out = np.empty((sums.size, 3), np.int32)
        m = self.model
        n = search(sums.ravel(), squares.ravel(), stride, layers, offsets, self._weights,
                   self._stage_thr, m.stage_first, m.stage_count, m.weak, m.nodes,
                   self._node_thr, self._leaves, m.width, m.height, out)
        hits = []
        for k, x, y in out[:n].tolist():
            s = scales[k]
            hits.append([int(np.rint(np.float32(x) * s)), int(np.rint(np.float32(y) * s)),
                         int(np.rint(np.float32(m.width) * s)),
                         int(np.rint(np.float32(m.height) * s))])
        return hits

    def detect(self, grey: np.ndarray, scale_factor: float, min_neighbors: int, min_size: int,
               max_size: int) -> list[tuple[int, int, int, int]]:
        """The objects found: raw hits grouped and clipped as ``detectMultiScale`` does.

        Args:
            grey: ``(h, w)`` uint8 image.
            scale_factor: scale step (> 1).
            min_neighbors: a group needs more than this many raw hits.
            min_size, max_size: window sides searched, in image pixels.
        """
        _check(grey, scale_factor)
        if _kernels() is None:
            return [tuple(hit) for hit in self._opencv_hits(grey, scale_factor, min_neighbors,
                                                             min_size, max_size)]
        return group(self.raw(grey, scale_factor, min_size, max_size), min_neighbors,
                     grey.shape)

    def _opencv_hits(self, grey, scale_factor, min_neighbors, min_size, max_size,
                     scales=None, band=None):
        """OpenCV's own search (a band as one call over its sizes: the same hits but for rows
        OpenCV's stripes leave out at the bottom)."""
        import cv2

        if self._opencv is None:
            self._opencv = threading.local()
        classifier = getattr(self._opencv, "c", None)
        if classifier is None:  # one per thread: a classifier keeps its images while it runs
            classifier = self._opencv.c = cv2.CascadeClassifier(str(self.path))
        if band is not None:
            wins = [int(np.rint(np.float32(self.window[0]) * s)) for s in scales]
            wins = [v for v in wins if band[0] <= v <= band[1]]
            if not wins:
                return []
            min_size, max_size = wins[0], wins[-1]
        hits = classifier.detectMultiScale(grey, scale_factor, min_neighbors,
                                           minSize=(min_size, min_size),
                                           maxSize=(max_size, max_size))
        return [[int(v) for v in hit] for hit in hits]


def _check(grey: np.ndarray, scale_factor: float) -> None:
    if not isinstance(grey, np.ndarray) or grey.ndim != 2 or grey.dtype != np.uint8:
        got = getattr(grey, "shape", type(grey).__name__), getattr(grey, "dtype", "")
        raise ValueError(f"a cascade searches a 2-D uint8 image, got {got}")
    if not scale_factor > 1:
        raise ValueError(f"the scale step must be above 1, got {scale_factor!r}")


def group(raw: list[list[int]], min_neighbors: int,
          shape: tuple[int, ...]) -> list[tuple[int, int, int, int]]:
    """Raw hits grouped (``cv2.groupRectangles(raw, min_neighbors, 0.2)``) and clipped to an
    image of ``shape`` -- what ``detectMultiScale`` does after its search."""
    import cv2

    if min_neighbors > 0 and raw:
        raw, _ = cv2.groupRectangles(raw, min_neighbors, 0.2)
    h, w = shape[:2]
    out = []
    for x, y, bw, bh in raw:
        x0, y0 = max(int(x), 0), max(int(y), 0)
        x1, y1 = min(int(x) + int(bw), w), min(int(y) + int(bh), h)
        if x1 > x0 and y1 > y0:
            out.append((x0, y0, x1 - x0, y1 - y0))
    return out
