"""Offline generator of the profile-face texture used by the synthetic camera.

OpenCV's profile cascade does not fire on a drawn head silhouette. Rather than teaching the
detector about synthetic frames, we change the pixels: starting from the drawn profile, a seeded
hill climb edits the brightness of the face region (smooth Gaussian blobs, only inside the head
outline) until the cascade's own stages accept it, scored with :class:`perception.haar.HaarCascade`
over shifted and rescaled windows so that OpenCV's multi-scale search with ``minNeighbors`` finds
it too. The result is a 28x28 grey texture, written as hex into
``perception/_profile_texture.py``. Run ``python -m perception.texture`` to regenerate it (same
seed, same texture); it takes a few minutes on one core.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

__all__ = ["PATCH", "make_texture", "score_patch"]

#: side of the texture in pixels.
PATCH = 28
_SCALES = (0.8, 0.9, 1.0, 1.1, 1.2)
_SHIFTS = (-2, 0, 2)


def _initial(r: int = 60) -> tuple[np.ndarray, np.ndarray]:
    """The untextured drawn profile's face region (grey) and the mask of the head in it."""
    import cv2

    from perception.render import _profile, _profile_outline, patch_box

    h = w = 4 * r
    cx = cy = 2 * r
    img = np.full((h, w, 3), (178, 186, 190), np.uint8)
    _profile(img, cx, cy, r, textured=False)
    mask = np.zeros((h, w), np.uint8)  # the head outline, drawn nose-right then mirrored
    cv2.fillPoly(mask, [_profile_outline(cx, cy, r)], 255)
    cv2.ellipse(mask, (cx - r // 10, cy - r // 10), (int(0.85 * r), int(0.95 * r)), 0, 0, 360,
                255, -1)
    mask = cv2.flip(mask, 1)
    x0, y0, s = patch_box(cx, cy, r)
    grey = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)[y0:y0 + s, x0:x0 + s]
    m = mask[y0:y0 + s, x0:x0 + s]
    grey = cv2.resize(grey, (PATCH, PATCH), interpolation=cv2.INTER_AREA).astype(float)
    m = cv2.resize(m, (PATCH, PATCH), interpolation=cv2.INTER_AREA) > 200
    return grey, m


def score_patch(cascade, patch: np.ndarray) -> np.ndarray:
    """Per-window scores (stages passed + sigmoid of the margin) over shifts and scales."""
    import cv2

    out = []
    for sc in _SCALES:
        n = round(PATCH * sc)
        img = cv2.resize(patch, (n, n), interpolation=cv2.INTER_LINEAR)
        c = (n - cascade.width) // 2
        corners = np.array([(c + dx, c + dy) for dx in _SHIFTS for dy in _SHIFTS])
        corners = np.clip(corners, 0, n - cascade.width)
        passed, margin = cascade.evaluate(img, corners)
        out.append(passed + 1.0 / (1.0 + np.exp(-4.0 * margin)))
    return np.concatenate(out)


def _detector_frames() -> list[tuple[object, tuple[int, int]]]:
    """The rendered profile views the final pass scores against (poses, lights, sizes)."""
    from perception.render import SceneView

    return [(SceneView("centre", pose, lighting=light, seed=seed), size)
            for pose in ("left_2", "right_2") for light in (0.6, 1.0, 1.25)
            for size, seed in (((320, 240), 3), ((320, 240), 8))]


def score_with_opencv(patch: np.ndarray, frames) -> np.ndarray:
    """Per frame: OpenCV's raw profile hits on the rendered frame (capped at 10, over 10) plus 2
    when the hits group into a detection with the detector's own parameters."""
    import cv2

    from perception import render as rmod
    from perception.cascade import group
    from perception.faces import FaceParams, _cascade

    p = FaceParams()
    rmod._TEXTURE[:] = [np.clip(np.round(patch), 0, 255).astype(np.uint8)]
    cascade = _cascade("profile")
    out = []
    for view, size in frames:
        grey = cv2.cvtColor(rmod.render(view, size), cv2.COLOR_BGR2GRAY)
        scale = p.work_height / grey.shape[0]
        grey = cv2.resize(grey, (round(grey.shape[1] * scale), p.work_height),
                          interpolation=cv2.INTER_AREA)
        if view.face_pose.startswith("right"):
            grey = cv2.flip(grey, 1)
        hits = cascade.raw(grey, p.scale_factor, p.min_size, min(grey.shape))
        grouped = group(hits, p.min_neighbors, grey.shape)
        out.append(min(len(hits), 10) / 10.0 + 2.0 * (len(grouped) > 0))
    rmod._TEXTURE.clear()
    return np.array(out)


def make_texture(iterations: int = 30000, seed: int = 0, verbose: bool = False,
                 start: np.ndarray | None = None, stage: int = 0) -> np.ndarray:
    """Hill-climb the profile texture against OpenCV's profile cascade.

    Args:
        iterations: number of proposed edits.
        seed: random seed (same seed, same texture).
        verbose: print progress every 2000 iterations.
        start: continue from this texture instead of the drawing.
        stage: 0 edits only inside the head outline and stays near the drawing; 1 (a second
            pass) may edit the whole square and scores only the cascade; 2 (a third pass)
            scores the rendered frames with OpenCV itself (:func:`score_with_opencv`).

    Returns:
        The ``PATCH x PATCH`` uint8 texture.
    """
    import cv2

    from perception.haar import HaarCascade

    cascade = HaarCascade(Path(cv2.data.haarcascades) / "haarcascade_profileface.xml")
    rng = np.random.default_rng(seed)
    init, mask = _initial()
    if stage:
        mask = np.ones_like(mask)
    weight = 2.0 if stage == 0 else 0.0
    yy, xx = np.mgrid[0:PATCH, 0:PATCH]
    inside = np.argwhere(mask)

    frames = _detector_frames() if stage == 2 else None

    def objective(p: np.ndarray) -> float:
        if frames is not None:
            return float(score_with_opencv(p, frames).sum())
        s = score_patch(cascade, p)
        return float(s.mean() + 0.5 * s.min() - weight * np.abs(p - init).mean() / 255.0)

    x = init.copy() if start is None else start.astype(float)
    best = objective(x)
    start = time.time()
    for it in range(iterations):
        cy, cx = inside[rng.integers(len(inside))]
        sigma = rng.uniform(0.7, 1.8)
        blob = np.exp(-((xx - cx) ** 2 + (yy - cy) ** 2) / (2 * sigma * sigma))
        y = np.where(mask, np.clip(x + rng.normal(0.0, 40.0) * blob, 0, 255), x)
        value = objective(y)
        if value >= best:
            x, best = y, value
        if verbose and it % 2000 == 0:
            print(f"{it:6d} objective {best:7.3f} {time.time() - start:6.1f} s", flush=True)
    return np.clip(np.round(x), 0, 255).astype(np.uint8)


_TEMPLATE = '''"""Generated by ``python -m perception.texture``
(seed {seed}, 2 x {iterations} iterations).

A {n}x{n} grey texture for the synthetic profile face; see :mod:`perception.texture`.
"""

import numpy as np

_HEX = (
{rows}
)


def texture() -> np.ndarray:
    """The texture as a ``({n}, {n})`` uint8 array."""
    return np.frombuffer(bytes.fromhex("".join(_HEX)), np.uint8).reshape({n}, {n})
'''


def main(argv: list[str] | None = None) -> int:
    """Regenerate ``perception/_profile_texture.py``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--iterations", type=int, default=30000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default=str(Path(__file__).with_name("_profile_texture.py")))
    args = parser.parse_args(argv)
    tex = make_texture(args.iterations, args.seed, verbose=True)
    tex = make_texture(args.iterations, args.seed + 1, verbose=True, start=tex, stage=1)
    tex = make_texture(args.iterations // 10, args.seed + 2, verbose=True, start=tex, stage=2)
    rows = "\n".join(f'    "{row.tobytes().hex()}"' for row in tex)
    Path(args.out).write_text(_TEMPLATE.format(seed=args.seed, iterations=args.iterations,
                                               n=PATCH, rows=rows))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
