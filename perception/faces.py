"""Faces and coarse head pose with the Haar cascades shipped in the OpenCV wheel.

Detection (a small real-time tracker rather than a brute-force search):

* The frame is reduced to ``work_height`` rows (120 by default: a face must span at least
  ``min_size`` = 20 of them, a sixth of the frame) and searched at scale step ``scale_factor``.
* Each search is OpenCV's ``detectMultiScale`` (same scales, windows, arithmetic, grouping: the
  same faces) run by the compiled evaluator of :mod:`perception.cascade`, about 2.5 times
  faster on one core.
* The frontal cascade runs first. Only when it fails does the profile cascade run, first on the
  image (it finds faces whose nose points to the image's left) and then on the mirrored image
  (nose to the right).
* A :class:`FaceTracker` remembers the last face: the next frame is searched only in a window
  around it, at sizes within ``[0.7, 1.4]`` of it, with the cascade that found it first. A full
  search is made when the window search fails.
* Given a thread pool (``FaceTracker(pool=...)``, e.g. from ``Perceiver(threads=2)``), a full
  search queues each cascade as tasks over bands of face sizes of the same search, frontal
  first, and groups each cascade's raw hits as the one call does: the same faces, in about
  half the wall time on two free cores. A face found cancels the later cascades' tasks not yet
  started.

Pose (classes of :data:`perception.vocabulary.POSES`, in the image's frame):

* a profile-cascade face is ``left_2`` (nose to image-left) or ``right_2``, with a nominal pan
  of -/+ 70 degrees;
* a frontal-cascade face gets pan and tilt from where its features (the box the cascade
  centres on eyes, nose and mouth) sit inside the head. The head is the region of the face's own
  skin colour (sampled in the box, compared in YCrCb) around the box. Features of a head of
  half-width ``R`` turned by ``pan`` move by about ``0.9 R sin(pan)``, so
  ``pan = asin((feature x - head centre x) / 0.9 R)``; tilt likewise from the vertical offset.
  ``|pan| >= pan_slight`` makes ``left_1``/``right_1``; ``tilt <= tilt_down`` makes ``down``;
  otherwise ``frontal``. Grey frames have no skin colour: their frontal faces are ``frontal``
  with pan and tilt 0.

Sign conventions: pan > 0 when the nose points to the image's right; tilt < 0 when the face
looks down.
"""

from __future__ import annotations

import threading
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from perception.cascade import Cascade, group

__all__ = ["Face", "FaceParams", "FaceTracker", "detect_face"]

_PROFILE_PAN = 70.0
#: feature-centre-to-chin distance of a level face, in face-box heights.
_CHIN_DROP = 0.42


@dataclass(frozen=True)
class FaceParams:
    """Parameters of face detection and pose.

    Attributes:
        work_height: frames taller than this are reduced to it before detection.
        scale_factor: scale step of the cascade search.
        min_neighbors: overlapping raw detections needed to accept a face.
        min_size: smallest face side, in working-image pixels.
        track_margin: the tracking window is the last box grown by this fraction on each side.
        pan_slight: |pan| in degrees from which a frontal face is ``left_1``/``right_1``.
        tilt_down: tilt in degrees at or below which a frontal face is ``down``.
    """

    work_height: int = 120
    scale_factor: float = 1.15
    min_neighbors: int = 3
    min_size: int = 20
    track_margin: float = 0.5
    pan_slight: float = 15.0
    tilt_down: float = -15.0


@dataclass(frozen=True)
class Face:
    """A detected face in frame pixels.

    Attributes:
        box: ``(x, y, w, h)``.
        detector: ``"frontal"``, ``"profile"`` (nose to image-left) or ``"profile_mirrored"``.
        pose: one of :data:`perception.vocabulary.POSES`.
        pan: degrees, positive with the nose to the image's right.
        tilt: degrees, negative looking down.
    """

    box: tuple[int, int, int, int]
    detector: str
    pose: str
    pan: float
    tilt: float


_CASCADES: dict[str, object] = {}
_FILES = {"frontal": "haarcascade_frontalface_alt2.xml", "profile": "haarcascade_profileface.xml"}
_CASCADES_LOCK = threading.Lock()


def _cascade(name: str):
    """The cascade ``name`` as a :class:`perception.cascade.Cascade` (loaded once per process;
    one object serves every thread)."""
    with _CASCADES_LOCK:
        if name not in _CASCADES:
            import cv2

            _CASCADES[name] = Cascade(Path(cv2.data.haarcascades) / _FILES[name])
        return _CASCADES[name]


def _search(grey: np.ndarray, kind: str, params: FaceParams, min_side: int,
            max_side: int) -> tuple[int, int, int, int] | None:
    """Run one cascade (``kind`` in frontal/profile/profile_mirrored); the largest hit."""
    import cv2

    img = cv2.flip(grey, 1) if kind == "profile_mirrored" else grey
    cascade = _cascade("frontal" if kind == "frontal" else "profile")
    hits = cascade.detect(img, params.scale_factor, params.min_neighbors, min_side, max_side)
    return _largest(hits, kind, img.shape[1])


def _largest(hits, kind: str, width: int) -> tuple[int, int, int, int] | None:
    """The largest of grouped ``hits`` in the searched image, unmirrored when ``kind`` says."""
    if len(hits) == 0:
        return None
    x, y, w, h = (int(v) for v in max(hits, key=lambda b: b[2] * b[3]))
    if kind == "profile_mirrored":
        x = width - x - w
    return x, y, w, h


#: the largest face side (working-image rows) of each band of a pooled search but the last:
#: bands of similar cost (20; 23; 26-30; 35-46; 53 up at scale step 1.15: 16, 13, 20, 28 and
#: 23 % of the compiled search on the bench photos), since the smallest sizes have the most
#: windows and OpenCV halves its window step from twice the cascade's size (40 rows) up. Five
#: bands keep two workers busy to the end of a search (1 to 4 bands measured no faster).
_BAND_EDGES = (20, 23, 30, 46)


def _bands(lo: int, hi: int) -> list[tuple[int, int]]:
    """The size range ``[lo, hi]`` cut after each of :data:`_BAND_EDGES` (empty bands left out)."""
    cuts = [lo - 1, *(e for e in _BAND_EDGES if lo <= e < hi), hi]
    return [(a + 1, b) for a, b in zip(cuts, cuts[1:], strict=False) if a < b]


def _band_hits(img: np.ndarray, kind: str, params: FaceParams, lo: int,
               hi: int) -> list[list[int]]:
    """Raw (ungrouped, unclipped) hits of one cascade's full search at the sizes ``[lo, hi]``,
    run in a pool thread (the compiled search releases the GIL)."""
    return _cascade("frontal" if kind == "frontal" else "profile").raw(
        img, params.scale_factor, params.min_size, min(img.shape[:2]), band=(lo, hi))


def _search_pooled(grey: np.ndarray, params: FaceParams, pool: Executor):
    """The full search with the cascades' bands run in ``pool``; same result as running the
    cascades of :data:`_ORDER` one by one with :func:`_search`.

    Every band of every cascade is queued at once, in that order, so a worker that finishes
    early starts on the next cascade; once a cascade finds a face the later tasks not yet
    started are cancelled (those already running are the only work wasted).
    """
    import cv2

    bands = _bands(params.min_size, min(grey.shape[:2]))
    images = {"frontal": grey, "profile": grey, "profile_mirrored": cv2.flip(grey, 1)}
    queued = [(kind, [pool.submit(_band_hits, images[kind], kind, params, lo, hi)
                      for lo, hi in bands]) for kind in _ORDER]
    for k, (kind, tasks) in enumerate(queued):
        raw = [hit for task in tasks for hit in task.result()]  # in OpenCV's order: by size
        if not raw:
            continue
        box = _largest(group(raw, params.min_neighbors, grey.shape), kind, grey.shape[1])
        if box is not None:
            for _, later in queued[k + 1:]:
                for task in later:
                    task.cancel()
            return box, kind
    return None


_ORDER = ("frontal", "profile", "profile_mirrored")


def _skin_mask(region: np.ndarray, box: tuple[int, int, int, int]) -> np.ndarray:
    """Pixels of the face's own skin colour: chromaticity and brightness near the cheeks'."""
    bx, by, w, h = box
    f = region.astype(np.float32) + 1.0
    total = f.sum(axis=2)
    chroma = f[..., 1:] / total[..., None]  # g and r chromaticity: brightness-free
    rows = slice(by + int(0.5 * h), by + int(0.7 * h))
    cheeks = [(slice(rows.start, rows.stop), slice(bx + int(0.12 * w), bx + int(0.3 * w))),
              (slice(rows.start, rows.stop), slice(bx + int(0.7 * w), bx + int(0.88 * w)))]
    ref_c = np.concatenate([chroma[c].reshape(-1, 2) for c in cheeks])
    ref_t = np.concatenate([total[c].ravel() for c in cheeks])
    if ref_c.size == 0:
        return np.zeros(region.shape[:2], bool)
    c0, t0 = np.median(ref_c, axis=0), float(np.median(ref_t))
    near = np.abs(chroma - c0).max(axis=2) <= 0.035
    return near & (total >= 0.45 * t0) & (total <= 1.8 * t0)


def _skin_pose(frame: np.ndarray, box: tuple[int, int, int, int]) -> tuple[float, float]:
    """Pan and tilt (degrees) of a frontal face from its features' place in the head."""
    x, y, w, h = box
    fh, fw = frame.shape[:2]
    x0, x1 = max(0, x - w // 2), min(fw, x + w + w // 2)
    y0, y1 = max(0, y - h // 2), min(fh, y + h + h // 2)
    bx, by = x - x0, y - y0
    skin = _skin_mask(frame[y0:y1, x0:x1], (bx, by, w, h))
    band = skin[by + int(0.25 * h):by + int(0.8 * h)]
    cols = band.mean(axis=0) >= 0.5
    fx = bx + w / 2.0
    left, right = _run_around(cols, int(fx))
    if right - left < w // 4:
        return 0.0, 0.0
    half = (right - left) / 2.0
    pan = np.degrees(np.arcsin(np.clip((fx - (left + right) / 2.0) / (0.9 * half), -1, 1)))
    # the chin: the last row below the features where the skin still spans half the head
    inner = skin[:, left:right + 1]
    rows = inner.mean(axis=1) >= 0.5
    fy = by + h / 2.0
    _, bottom = _run_around(rows, int(fy))
    drop = (bottom - fy) / h  # feature centre to chin, in face boxes
    tilt = -np.degrees(np.arcsin(np.clip((_CHIN_DROP - drop) / 0.45, -1, 1)))
    return float(pan), float(tilt)


def _run_around(flags: np.ndarray, i: int) -> tuple[int, int]:
    """The contiguous run of True in ``flags`` containing (or nearest to) index ``i``."""
    if not flags.any():
        return 0, -1
    i = int(np.clip(i, 0, len(flags) - 1))
    if not flags[i]:
        idx = np.flatnonzero(flags)
        i = int(idx[np.argmin(np.abs(idx - i))])
    lo = i
    while lo > 0 and flags[lo - 1]:
        lo -= 1
    hi = i
    while hi < len(flags) - 1 and flags[hi + 1]:
        hi += 1
    return lo, hi


def _classify(frame: np.ndarray, box: tuple[int, int, int, int], kind: str,
              params: FaceParams) -> Face:
    if kind != "frontal":
        pan = -_PROFILE_PAN if kind == "profile" else _PROFILE_PAN
        return Face(box, kind, "left_2" if pan < 0 else "right_2", pan, 0.0)
    pan, tilt = _skin_pose(frame, box) if frame.ndim == 3 else (0.0, 0.0)
    if tilt <= params.tilt_down:
        pose = "down"
    elif abs(pan) >= params.pan_slight:
        pose = "left_1" if pan < 0 else "right_1"
    else:
        pose = "frontal"
    return Face(box, kind, pose, round(pan, 1), round(tilt, 1))


class FaceTracker:
    """Find one face per frame, searching near the last one first.

    Args:
        params: detection and pose parameters.
        pool: an executor (e.g. a ``ThreadPoolExecutor`` of two threads) for the full search's
            cascade bands; ``None`` searches in the calling thread. Same faces either way.
    """

    def __init__(self, params: FaceParams = FaceParams(), pool: Executor | None = None) -> None:
        self.params = params
        self.pool = pool
        self.last: Face | None = None
        self.full_searches = 0

    def reset(self) -> None:
        """Forget the last face (the next frame gets a full search)."""
        self.last = None

    def detect(self, frame: np.ndarray) -> Face | None:
        """The face in a BGR (or grey) frame, or ``None``.

        Args:
            frame: ``(h, w, 3)`` uint8 BGR or ``(h, w)`` uint8 grey image.
        """
        import cv2

        p = self.params
        grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) if frame.ndim == 3 else frame
        scale = min(1.0, p.work_height / grey.shape[0])
        if scale < 1.0:
            grey = cv2.resize(grey, (max(1, round(grey.shape[1] * scale)), p.work_height),
                              interpolation=cv2.INTER_AREA)
        found = self._track(grey, scale) if self.last is not None else None
        if found is None:
            self.full_searches += 1
            found = self._full_search(grey)
        if found is None:
            self.last = None
            return None
        (x, y, w, h), kind = found
        frame_box = (int(x / scale), int(y / scale), int(w / scale), int(h / scale))
        self.last = _classify(frame, frame_box, kind, p)
        return self.last

    def _full_search(self, grey: np.ndarray):
        p = self.params
        if self.pool is not None:
            return _search_pooled(grey, p, self.pool)
        side = min(grey.shape[:2])
        for kind in _ORDER:
            box = _search(grey, kind, p, p.min_size, side)
            if box is not None:
                return box, kind
        return None

    def _track(self, grey: np.ndarray, scale: float):
        p = self.params
        x, y, w, h = (round(v * scale) for v in self.last.box)
        m = int(p.track_margin * max(w, h))
        x0, y0 = max(0, x - m), max(0, y - m)
        x1, y1 = min(grey.shape[1], x + w + m), min(grey.shape[0], y + h + m)
        roi = grey[y0:y1, x0:x1]
        lo = max(p.min_size, int(0.7 * w))
        hi = min(int(1.4 * w) + 1, min(roi.shape[:2]))
        if hi < lo:
            return None
        order = ("frontal",) + tuple(k for k in _ORDER[1:] if k == self.last.detector) + tuple(
            k for k in _ORDER[1:] if k != self.last.detector)
        for kind in order:
            box = _search(roi, kind, p, lo, hi)
            if box is not None:
                bx, by, bw, bh = box
                return (bx + x0, by + y0, bw, bh), kind
        return None


def detect_face(frame: np.ndarray, params: FaceParams = FaceParams()) -> Face | None:
    """Detect the face in one frame with a full search (no tracking state)."""
    return FaceTracker(params).detect(frame)
