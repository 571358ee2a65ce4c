"""A small numpy evaluator of OpenCV's Haar cascades (stump-based ones).

OpenCV's ``CascadeClassifier`` only says "face" or "no face" for a window. To build a synthetic
face the real detector responds to (see :mod:`perception.texture`) we need a graded score: how
many stages a window passes and by what margin. This module reads the cascade XML shipped in the
wheel (with :func:`perception.cascade.parse_cascade`) and evaluates windows the way OpenCV does
(variance-normalised Haar features on an integral image, stage sums of stump leaves against stage
thresholds). It is used offline, by the texture generator; the detector itself uses the compiled
search of :mod:`perception.cascade`, which gives OpenCV's detections.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["HaarCascade"]


@dataclass
class _Stage:
    threshold: float
    features: np.ndarray  # (n, 3, 5) rects x, y, w, h, weight
    thresholds: np.ndarray  # (n,)
    leaves: np.ndarray  # (n, 2)


class HaarCascade:
    """A stump-based Haar cascade read from an OpenCV XML file.

    Args:
        path: the cascade file, e.g. ``cv2.data.haarcascades + "haarcascade_profileface.xml"``.
    """

    def __init__(self, path: str | Path) -> None:
        from perception.cascade import parse_cascade

        m = parse_cascade(path)
        if m.weak[:, 0].max() != 1:
            raise ValueError(f"{path}: only stump cascades are supported")
        self.width, self.height = m.width, m.height
        table = np.concatenate([m.rects.astype(np.float64), m.weights[:, :, None]], axis=2)
        self.stages: list[_Stage] = []
        for threshold, first, count in zip(m.stage_threshold, m.stage_first, m.stage_count,
                                           strict=True):
            weak = m.weak[first:first + count]
            nodes = weak[:, 1]
            self.stages.append(_Stage(float(threshold), table[m.nodes[nodes, 2]],
                                      m.node_threshold[nodes],
                                      np.stack([m.leaves[weak[:, 2]], m.leaves[weak[:, 2] + 1]],
                                               axis=1)))

    def evaluate(self, grey: np.ndarray, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Score windows of the cascade's size at the given top-left corners.

        Args:
            grey: a 2-D grey image (any numeric type).
            corners: ``(n, 2)`` integer array of window corners ``x, y``.

        Returns:
            ``(passed, margin)``: the number of stages each window passes (``len(stages)`` for a
            detection) and the stage-sum margin of the last stage it reached.
        """
        import cv2

        img = grey.astype(np.float64)
        ii = cv2.integral(img)
        sq = cv2.integral(img * img)
        x = corners[:, 0][:, None].astype(int)
        y = corners[:, 1][:, None].astype(int)

        def box(table, x0, y0, w, h):
            return table[y0 + h, x0 + w] - table[y0, x0 + w] - table[y0 + h, x0] + table[y0, x0]

        w2, h2 = self.width - 2, self.height - 2
        area = w2 * h2
        s1 = box(ii, x[:, 0] + 1, y[:, 0] + 1, w2, h2)
        s2 = box(sq, x[:, 0] + 1, y[:, 0] + 1, w2, h2)
        nf = area * s2 - s1 * s1
        nf = np.where(nf > 0, np.sqrt(np.maximum(nf, 1e-12)), 1.0)
        n = len(corners)
        passed = np.zeros(n, dtype=int)
        alive = np.ones(n, dtype=bool)
        margin = np.zeros(n)
        for stage in self.stages:
            idx = np.flatnonzero(alive)  # only windows still alive are evaluated
            if idx.size == 0:
                break
            f = stage.features
            xa, ya = x[idx], y[idx]
            value = np.zeros((idx.size, len(f)))
            for r in range(3):
                fx, fy, fw, fh = (f[:, r, j].astype(int)[None] for j in range(4))
                value += f[:, r, 4][None] * box(ii, xa + fx, ya + fy, fw, fh)
            value /= nf[idx, None]
            total = np.where(value < stage.thresholds[None], stage.leaves[None, :, 0],
                             stage.leaves[None, :, 1]).sum(axis=1)
            m = total - stage.threshold
            margin[idx] = m
            ok = m >= 0
            alive[idx] = ok
            passed[idx] += ok
        return passed, margin
