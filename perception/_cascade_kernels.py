"""The numba kernels of :mod:`perception.cascade` (imported on first use: it compiles them).

Integral images of all scales are stacked in one buffer of row length ``stride``; a window is
the buffer index of its top-left corner. Indices are unsigned so that numba emits no
negative-index wrap-around checks (they cost more than the arithmetic they guard).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["offsets", "search"]


@njit(cache=True, nogil=True)
def offsets(rects, stride):
    """Buffer offsets of the four corners of every feature rectangle, for row length
    ``stride``: ``(features, 3, 4)`` uint32 (top-left, top-right, bottom-left, bottom-right)."""
    n = rects.shape[0]
    out = np.zeros((n, 3, 4), np.uint32)
    for i in range(n):
        for r in range(3):
            x, y, w, h = rects[i, r, 0], rects[i, r, 1], rects[i, r, 2], rects[i, r, 3]
            out[i, r, 0] = y * stride + x
            out[i, r, 1] = y * stride + x + w
            out[i, r, 2] = (y + h) * stride + x
            out[i, r, 3] = (y + h) * stride + x + w
    return out


@njit(cache=True, nogil=True)
def _feature(sums, base, norm, n, ofs, weights, f, out):
    """``out[a]`` = feature ``f`` of the windows at ``base[:n]``, normalised by ``norm[:n]``,
    in single precision as OpenCV computes it."""
    a0, a1, a2, a3 = ofs[f, 0, 0], ofs[f, 0, 1], ofs[f, 0, 2], ofs[f, 0, 3]
    b0, b1, b2, b3 = ofs[f, 1, 0], ofs[f, 1, 1], ofs[f, 1, 2], ofs[f, 1, 3]
    w0, w1, w2 = weights[f, 0], weights[f, 1], weights[f, 2]
    if w2 == 0:
        for a in range(n):
            p = base[a]
            r0 = sums[p + a0] - sums[p + a1] - sums[p + a2] + sums[p + a3]
            r1 = sums[p + b0] - sums[p + b1] - sums[p + b2] + sums[p + b3]
            out[a] = (w0 * np.float32(r0) + w1 * np.float32(r1)) * norm[a]
    else:
        c0, c1, c2, c3 = ofs[f, 2, 0], ofs[f, 2, 1], ofs[f, 2, 2], ofs[f, 2, 3]
        for a in range(n):
            p = base[a]
            r0 = sums[p + a0] - sums[p + a1] - sums[p + a2] + sums[p + a3]
            r1 = sums[p + b0] - sums[p + b1] - sums[p + b2] + sums[p + b3]
            r2 = sums[p + c0] - sums[p + c1] - sums[p + c2] + sums[p + c3]
            v = w0 * np.float32(r0) + w1 * np.float32(r1)
            v += w2 * np.float32(r2)
            out[a] = v * norm[a]


@njit(cache=True, nogil=True)
def _stage(sums, base, norm, n, ofs, weights, first, count, weak, nodes, node_thr, leaves, acc,
           v0, v1):
    """``acc[a]`` = the stage sum of window ``a`` (weak classifiers ``first .. first+count``)."""
    for a in range(n):
        acc[a] = 0.0
    for wi in range(first, first + count):
        nd, lf = weak[wi, 1], weak[wi, 2]
        _feature(sums, base, norm, n, ofs, weights, nodes[nd, 2], v0)
        t0 = node_thr[nd]
        if weak[wi, 0] == 1:  # a stump
            l0, l1 = np.float64(leaves[lf]), np.float64(leaves[lf + 1])
            for a in range(n):
                acc[a] += l0 if v0[a] < t0 else l1
        else:  # two nodes: the root leads to leaf 0 on one side and to node 1 on the other
            _feature(sums, base, norm, n, ofs, weights, nodes[nd + 1, 2], v1)
            t1 = node_thr[nd + 1]
            la, lb = np.float64(leaves[lf]), np.float64(leaves[lf + 1])
            lc = np.float64(leaves[lf + 2])
            if nodes[nd, 0] == 0:
                for a in range(n):
                    acc[a] += la if v0[a] < t0 else (lb if v1[a] < t1 else lc)
            else:
                for a in range(n):
                    acc[a] += (lb if v1[a] < t1 else lc) if v0[a] < t0 else la


@njit(cache=True, nogil=True)
def search(sums, squares, stride, layers, ofs, weights, stage_thr, stage_first, stage_count,
           weak, nodes, node_thr, leaves, win_w, win_h, out):
    """Raw hits of the cascade over the stacked scales.

    Args:
        sums, squares: the stacked integral images of the grey levels and their squares.
        stride: their row length.
        layers: ``(scales, 5)`` rows ``first row, width, height, window step, rows searched``
            of each scale (windows start at rows ``0, step, ...`` below the last).
        ofs: :func:`offsets` for ``stride``.
        weights .. leaves: the cascade (single-precision values as OpenCV keeps them).
        win_w, win_h: the detection window.
        out: ``(>= hits, 3)`` int32, filled with ``scale index, x, y`` of each hit.

    Returns:
        The number of hits.
    """
    nmax = 0
    for li in range(layers.shape[0]):
        step = layers[li, 3]
        nx = (layers[li, 1] + 1 - win_w + step - 1) // step
        ny = (layers[li, 4] + step - 1) // step
        nmax = max(nmax, nx * ny)
    base = np.empty(nmax, np.uint32)
    norm = np.empty(nmax, np.float32)
    pos = np.empty(nmax, np.int32)
    valid = np.empty(nmax, np.bool_)
    acc = np.empty(nmax, np.float64)
    v0 = np.empty(nmax, np.float32)
    v1 = np.empty(nmax, np.float32)
    # the inner (w-2) x (h-2) rectangle, over which OpenCV normalises
    q0, q1 = stride + 1, stride + win_w - 1
    q2, q3 = (win_h - 1) * stride + 1, (win_h - 1) * stride + win_w - 1
    area = np.float64((win_w - 2) * (win_h - 2))
    hits = 0
    for li in range(layers.shape[0]):
        row0, step = layers[li, 0], layers[li, 3]
        nx = (layers[li, 1] + 1 - win_w + step - 1) // step
        ny = (layers[li, 4] + step - 1) // step
        n = nx * ny
        k = 0
        for j in range(ny):
            for i in range(nx):
                p = np.uint32((row0 + j * step) * stride + i * step)
                base[k] = p
                s1 = sums[p + q0] - sums[p + q1] - sums[p + q2] + sums[p + q3]
                s2 = np.uint32(squares[p + q0] - squares[p + q1] - squares[p + q2]
                               + squares[p + q3])
                nf = area * np.float64(s2) - np.float64(s1) * np.float64(s1)
                if nf > 0.0:
                    r = np.float32(1.0 / np.sqrt(nf))
                    norm[k] = r
                    valid[k] = area * np.float64(r) < 0.1  # standard deviation above 10
                else:
                    norm[k] = np.float32(1.0)
                    valid[k] = False
                k += 1
        # the first stage on every window of the grid, then OpenCV's scan: a window the
        # first stage rejects makes it skip the next one in the row
        _stage(sums, base, norm, n, ofs, weights, stage_first[0], stage_count[0], weak, nodes,
               node_thr, leaves, acc, v0, v1)
        alive = 0
        for j in range(ny):
            i = 0
            while i < nx:
                k = j * nx + i
                if valid[k]:
                    if acc[k] < stage_thr[0]:
                        i += 2
                        continue
                    base[alive] = base[k]
                    norm[alive] = norm[k]
                    pos[alive] = k
                    alive += 1
                i += 1
        for st in range(1, stage_thr.shape[0]):
            if alive == 0:
                break
            _stage(sums, base, norm, alive, ofs, weights, stage_first[st], stage_count[st],
                   weak, nodes, node_thr, leaves, acc, v0, v1)
            kept = 0
            threshold = stage_thr[st]
            for a in range(alive):
                if acc[a] >= threshold:
                    base[kept] = base[a]
                    norm[kept] = norm[a]
                    pos[kept] = pos[a]
                    kept += 1
            alive = kept
        for a in range(alive):
            out[hits, 0] = li
            out[hits, 1] = (pos[a] % nx) * step
            out[hits, 2] = (pos[a] // nx) * step
            hits += 1
    return hits
