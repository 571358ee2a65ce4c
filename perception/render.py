"""The synthetic camera: draw what the robot's camera sees in the simulator's scene.

The simulator fills in a :class:`SceneView` (where the head looks, the caregiver's head pose,
which toy or fruit is at which place, the light) and :func:`render` draws a BGR frame that the
real perception pipeline then reads, so a simulated episode runs on real pixels.

Looking at ``centre`` shows the caregiver (head and shoulders) in one of the six poses of
:data:`perception.vocabulary.POSES`; looking at any other place shows the object at that
place on the wall or the table, or the empty background.

How the faces are drawn (and why the real detector finds them): the frontal, slightly turned
(``left_1``/``right_1``) and ``down`` faces are cartoon faces -- a skin ellipse with dark eyes,
brows, nose shadow and mouth -- which OpenCV's frontal Haar cascade accepts as they are. The
profile cascade does not fire on a drawn silhouette, so the profile faces (``left_2``/``right_2``)
carry a 28x28 grey texture inside the face outline that was *optimised offline against the
profile cascade itself* (:mod:`perception.texture`, stored in :mod:`perception._profile_texture`).
The detector is not told that a frame is synthetic; it sees pixels the cascade responds to.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from perception.appearance import Appearance, FruitLook, blur_kernel
from perception.errors import PerceptionError
from perception.vocabulary import COLOURS, OBJECT_PLACES, PLACES, POSES

__all__ = ["OBJECT_KINDS", "SceneView", "render"]

_SKIN = (120, 152, 200)
_HAIR = (30, 40, 60)
_SHIRT = (120, 80, 60)
_WALL = (178, 186, 190)
_TABLE = (112, 122, 136)
_PALETTE = {"red": (40, 40, 205), "orange": (20, 125, 245), "yellow": (40, 215, 235),
            "green": (50, 165, 60), "blue": (200, 95, 40), "purple": (150, 50, 130)}


@dataclass(frozen=True)
class SceneView:
    """What the camera sees: filled in by the simulator, drawn by :func:`render`.

    Attributes:
        looking_at: the place the head looks at (one of :data:`perception.vocabulary.PLACES`).
        face_pose: the caregiver's head pose (one of :data:`POSES`), or ``None`` when nobody
            is there; only drawn when ``looking_at == "centre"``.
        objects: place -> object kind (``apple``, ``lemon``, ``orange``, ``lime``) or a colour
            name (a toy block of that colour, see :data:`perception.vocabulary.COLOURS`).
        lighting: brightness gain of the scene light (1.0 normal, 0.5 dim, 1.4 bright).
        seed: seeds the small random parts (object jitter, sensor noise, light tint).
        appearance: how a camera in a real room sees the scene (light colour and white
            balance, blur, noise, each fruit's shade, shape, size, place and occlusion; see
            :mod:`perception.appearance`), or ``None`` for the plain drawing with a small
            random tint and noise.
    """

    looking_at: str
    face_pose: str | None = "frontal"
    objects: Mapping[str, str] = field(default_factory=dict)
    lighting: float = 1.0
    seed: int = 0
    appearance: Appearance | None = None

    def __post_init__(self) -> None:
        if self.looking_at not in PLACES:
            raise PerceptionError(f"unknown place {self.looking_at!r}; use one of {PLACES}")
        if self.face_pose is not None and self.face_pose not in POSES:
            raise PerceptionError(f"unknown face pose {self.face_pose!r}; use one of {POSES} "
                                  "or None")
        for place, kind in self.objects.items():
            if place not in OBJECT_PLACES:
                raise PerceptionError(f"objects cannot be at {place!r}; use one of "
                                      f"{OBJECT_PLACES}")
            if kind not in OBJECT_KINDS and kind not in _PALETTE:
                raise PerceptionError(f"unknown object {kind!r}; use one of "
                                      f"{sorted(OBJECT_KINDS) + sorted(_PALETTE)}")
        if not 0.05 <= float(self.lighting) <= 3.0:
            raise PerceptionError(f"lighting {self.lighting!r} is out of range; use 0.05..3.0")


def _fruit(colour: tuple[int, int, int], aspect: float, stem: bool) -> Callable:
    def draw(img: np.ndarray, cx: int, cy: int, r: int, rng: np.random.Generator) -> None:
        import cv2

        h, w = img.shape[:2]
        yy, xx = np.mgrid[0:h, 0:w]
        d = ((xx - cx) / (r * aspect)) ** 2 + ((yy - cy) / r) ** 2
        inside = d <= 1.0
        # a lit sphere: brighter toward the upper left, darker at the rim
        light = 0.8 + 0.35 * np.clip(1 - (((xx - cx + 0.35 * r) / r) ** 2
                                          + ((yy - cy + 0.35 * r) / r) ** 2), 0, 1) - 0.15 * d
        shaded = np.clip(np.array(colour, float)[None, None] * light[..., None], 0, 255)
        img[inside] = shaded[inside].astype(np.uint8)
        if stem:
            cv2.line(img, (cx, cy - r + 2), (cx + r // 6, cy - r - r // 4), (30, 60, 90),
                     max(1, r // 10))
            cv2.ellipse(img, (cx + r // 4, cy - r - r // 8), (r // 4, r // 8), -20, 0, 360,
                        (40, 140, 50), -1)
    return draw


def _block(colour: tuple[int, int, int]) -> Callable:
    def draw(img: np.ndarray, cx: int, cy: int, r: int, rng: np.random.Generator) -> None:
        import cv2

        dark = tuple(int(c * 0.7) for c in colour)
        cv2.rectangle(img, (cx - r, cy - r), (cx + r, cy + r), dark, -1)
        cv2.rectangle(img, (cx - r + 2, cy - r + 2), (cx + r - r // 5, cy + r - r // 5), colour,
                      -1)
    return draw


#: object kind -> drawing function ``(img, cx, cy, radius, rng)``.
OBJECT_KINDS: dict[str, Callable] = {
    "apple": _fruit(_PALETTE["red"], 1.0, True),
    "orange": _fruit(_PALETTE["orange"], 1.0, False),
    "lemon": _fruit(_PALETTE["yellow"], 1.3, False),
    "lime": _fruit(_PALETTE["green"], 1.0, False),
}
OBJECT_KINDS.update({f"{name}_block": _block(c) for name, c in _PALETTE.items()})
assert set(_PALETTE) <= set(COLOURS)


def _frontal(img: np.ndarray, cx: int, cy: int, r: int, yaw: float, pitch: float) -> None:
    """A cartoon face; ``yaw`` > 0 turns the nose to image-right, ``pitch`` > 0 looks down."""
    import cv2

    cv2.ellipse(img, (cx, cy - r // 6), (int(r * 1.05), int(r * 1.3)), 0, 0, 360, _HAIR, -1)
    cv2.ellipse(img, (cx, cy - r // 20), (r, int(r * 1.15)), 0, 0, 360, _SKIN, -1)
    sy, cp = np.sin(np.radians(yaw)), np.cos(np.radians(yaw))
    spit = np.sin(np.radians(pitch))
    # the hair covers the crown down to the hairline; a head looking down shows more crown
    hairline = cy - int(r * (0.95 - 0.45 * spit))
    crown = cy - int(1.25 * r)
    cv2.ellipse(img, (cx, hairline), (int(r * 0.98), hairline - crown), 0, 180, 360, _HAIR, -1)

    def at(x: float, y: float, z: float) -> tuple[int, int]:
        return (int(cx + (x * cp + z * sy) * r), int(cy + (y + 0.75 * spit) * r))

    eye_h = max(2, int(r * 0.11 * (1 - 0.5 * spit)))
    for ex in (-0.38, 0.38):
        cv2.ellipse(img, at(ex, -0.18, 0.85), (int(r * 0.2), eye_h), 0, 0, 360, (40, 40, 40), -1)
        cv2.ellipse(img, at(ex, -0.40, 0.9), (int(r * 0.25), max(2, r // 14)), 0, 0, 360,
                    (40, 50, 70), -1)
    cv2.ellipse(img, at(0, 0.18, 1.0), (max(2, r // 8), int(r * 0.22)), 0, 0, 360,
                (100, 130, 180), -1)
    cv2.ellipse(img, at(0, 0.55, 0.9), (int(r * 0.33), max(2, r // 9)), 0, 0, 360, (60, 60, 140),
                -1)


def _profile_outline(cx: int, cy: int, r: int) -> np.ndarray:
    pts = [(0.2, -1.0), (0.6, -0.8), (0.78, -0.45), (0.8, -0.3), (0.75, -0.15), (1.05, 0.2),
           (1.02, 0.27), (0.8, 0.3), (0.82, 0.42), (0.76, 0.48), (0.8, 0.55), (0.72, 0.65),
           (0.75, 0.8), (0.6, 0.92), (0.2, 0.85), (-0.2, 0.5)]
    return np.array([(cx + x * r, cy + y * r) for x, y in pts], np.int32)


#: where the profile texture goes: centre offset (toward the nose, down) and side, in head radii.
PROFILE_PATCH = (0.4, 0.05, 1.3)


def _profile(img: np.ndarray, cx: int, cy: int, r: int, textured: bool = True) -> None:
    """A profile head with the nose toward image-left (the side OpenCV's profile cascade
    detects without mirroring)."""
    import cv2

    w = img.shape[1]
    flipped = np.ascontiguousarray(img[:, ::-1])
    _profile_geometry(flipped, w - 1 - cx, cy, r)
    img[:] = cv2.flip(flipped, 1)
    if textured:
        _apply_texture(img, cx, cy, r, _texture())


#: the profile texture in use (``None``: load :mod:`perception._profile_texture` on first use;
#: :mod:`perception.texture` sets candidates here while it optimises them).
_TEXTURE: list[np.ndarray] = []


def _texture() -> np.ndarray:
    if not _TEXTURE:
        from perception._profile_texture import texture

        _TEXTURE.append(texture())
    return _TEXTURE[0]


def _profile_geometry(img: np.ndarray, cx: int, cy: int, r: int) -> None:
    """The drawn profile (no texture), nose toward image-right."""
    import cv2

    cv2.ellipse(img, (cx - r // 10, cy - r // 10), (int(0.85 * r), int(0.95 * r)), 0, 0, 360,
                _SKIN, -1)
    cv2.fillPoly(img, [_profile_outline(cx, cy, r)], _SKIN)
    cv2.ellipse(img, (cx - r // 4, cy - int(0.3 * r)), (int(0.8 * r), int(0.75 * r)), 0, 100,
                330, _HAIR, -1)
    cv2.ellipse(img, (cx - r // 10, cy - r // 10), (int(0.85 * r), int(0.95 * r)), 0, 120, 300,
                _HAIR, -1)
    cv2.ellipse(img, (cx - r // 20, cy + r // 20), (int(0.12 * r), int(0.2 * r)), 0, 0, 360,
                (110, 140, 190), -1)
    cv2.ellipse(img, (cx + int(0.58 * r), cy - int(0.15 * r)), (int(0.1 * r), int(0.06 * r)),
                0, 0, 360, (40, 40, 40), -1)
    cv2.ellipse(img, (cx + int(0.58 * r), cy - int(0.33 * r)), (int(0.16 * r), int(0.05 * r)),
                -10, 0, 360, (40, 50, 70), -1)
    cv2.ellipse(img, (cx + int(0.78 * r), cy + int(0.45 * r)), (int(0.08 * r), int(0.08 * r)),
                0, 0, 360, (60, 60, 140), -1)


def patch_box(cx: int, cy: int, r: int) -> tuple[int, int, int]:
    """Corner and side ``(x0, y0, side)`` of the texture of a nose-left profile head."""
    dx, dy, side = PROFILE_PATCH
    s = int(side * r)
    return cx - int(dx * r) - s // 2, cy + int(dy * r) - s // 2, s


def _apply_texture(img: np.ndarray, cx: int, cy: int, r: int, tex: np.ndarray) -> None:
    """Modulate the brightness of the face region by a grey texture (keeps the skin hue)."""
    import cv2

    x0, y0, s = patch_box(cx, cy, r)
    h, w = img.shape[:2]
    if x0 < 0 or y0 < 0 or x0 + s > w or y0 + s > h or s < 8:
        return
    grey = cv2.resize(tex.astype(np.float32), (s, s), interpolation=cv2.INTER_CUBIC)
    region = img[y0:y0 + s, x0:x0 + s].astype(np.float32)
    lum = region @ np.array([0.114, 0.587, 0.299], np.float32)
    gain = np.clip(grey, 0, 255) / np.maximum(lum, 1.0)
    out = region * gain[..., None]
    # beyond the skin channel range keep grey: clip, then fill what clipping lost with grey
    img[y0:y0 + s, x0:x0 + s] = np.clip(out, 0, 255).astype(np.uint8)


def _face(img: np.ndarray, pose: str, cx: int, cy: int, r: int) -> None:
    import cv2

    draw = _POSE_DRAWERS[pose]
    if draw is None:  # a right-side pose: draw the left one in a mirror
        flipped = np.ascontiguousarray(img[:, ::-1])
        _POSE_DRAWERS[pose.replace("right", "left")](flipped, img.shape[1] - 1 - cx, cy, r)
        img[:] = cv2.flip(flipped, 1)
        return
    draw(img, cx, cy, r)


_POSE_DRAWERS: dict[str, Callable] = {
    "frontal": lambda img, cx, cy, r: _frontal(img, cx, cy, r, 0.0, 0.0),
    "left_1": lambda img, cx, cy, r: _frontal(img, cx, cy, r, -30.0, 0.0),
    "left_2": _profile,
    "down": lambda img, cx, cy, r: _frontal(img, cx, cy, r, 0.0, 35.0),
    "right_1": None,
    "right_2": None,
}


def _background(h: int, w: int, looking_at: str) -> np.ndarray:
    return _background_cached(h, w, looking_at.endswith("down") and looking_at != "centre")


@functools.lru_cache(maxsize=16)
def _background_cached(h: int, w: int, table: bool) -> np.ndarray:
    img = np.empty((h, w, 3), np.float32)
    ramp = np.linspace(1.05, 0.9, h, dtype=np.float32)[:, None, None]
    img[:] = np.array(_WALL, np.float32) * ramp
    if table:
        top = int(h * 0.3)
        img[top:] = np.array(_TABLE, np.float32) * ramp[top:]
    out = img.clip(0, 255).astype(np.uint8)
    out.flags.writeable = False
    return out


def _draw_look(img: np.ndarray, kind: str, cx: int, cy: int, r: int, look: FruitLook) -> None:
    """A fruit in one of its real shades and shapes, lit from the upper left, perhaps partly
    behind the caregiver's hand (drawn in the fruit's bounding box only)."""
    import cv2

    h, w = img.shape[:2]
    ext = int(r * max(look.aspect, 1.0) * (1.0 + look.lumps)) + 3
    x0, x1, y0, y1 = max(0, cx - ext), min(w, cx + ext + 1), max(0, cy - ext), min(h, cy + ext + 1)
    if x0 < x1 and y0 < y1:
        rng = np.random.default_rng(look.texture)
        yy, xx = np.mgrid[y0:y1, x0:x1].astype(np.float32)
        dx, dy = (xx - cx) / r, (yy - cy) / r
        a = np.radians(look.angle)
        u = (dx * np.cos(a) + dy * np.sin(a)) / look.aspect
        v = -dx * np.sin(a) + dy * np.cos(a)
        rho = np.hypot(u, v)
        edge = 1.0 + look.lumps * np.sin(look.lobes * np.arctan2(v, u) + rng.uniform(0, 6.3))
        d = rho / edge
        inside = d <= 1.0
        if inside.any():
            # the second colour: a smooth random field over the skin, cut to cover `patch`
            mix = np.zeros_like(d)
            if look.patch > 0.0:
                f = sum(np.sin(rng.uniform(1.2, 3.5) * (u * np.cos(t) + v * np.sin(t))
                               + rng.uniform(0, 6.3))
                        for t in rng.uniform(0, np.pi, 3))
                cut = float(np.quantile(f[inside], 1.0 - look.patch))
                mix = np.clip((f - cut) / 0.3 + 0.5, 0.0, 1.0)
            base = (np.array(look.colour, np.float32)[None, None] * (1.0 - mix[..., None])
                    + np.array(look.patch_colour, np.float32)[None, None] * mix[..., None])
            # a sphere lit from the upper left: Lambert shading and a specular highlight
            nz = np.sqrt(np.clip(1.0 - d * d, 0.0, 1.0))
            nx, ny = dx / max(look.aspect, 1.0), dy
            lam = np.clip(-0.45 * nx - 0.5 * ny + 0.74 * nz, 0.0, 1.0)
            spec = look.highlight * np.clip(-0.25 * nx - 0.28 * ny + 0.93 * nz, 0.0, 1.0) ** 40
            pores = 1.0 + 0.04 * rng.standard_normal(d.shape).astype(np.float32)
            px = base * ((0.35 + 0.75 * lam) * pores)[..., None] + 255.0 * spec[..., None]
            region = img[y0:y1, x0:x1]
            region[inside] = np.clip(px[inside], 0, 255).astype(np.uint8)
    if kind == "apple":
        top = cy - r
        cv2.line(img, (cx, top + 2), (cx + r // 6, top - r // 4), (30, 60, 90), max(1, r // 10))
        cv2.ellipse(img, (cx + r // 4, top - r // 8), (r // 4, r // 8), -20, 0, 360,
                    (40, 140, 50), -1)
    if look.hand > 0.0:
        _hand(img, cx, cy, r, look)


def _hand(img: np.ndarray, cx: int, cy: int, r: int, look: FruitLook) -> None:
    """The caregiver's hand and arm, reaching ``look.hand`` of the fruit's diameter into it
    from the side ``look.hand_angle``."""
    import cv2

    a = np.radians(look.hand_angle)
    ux, uy = float(np.cos(a)), float(np.sin(a))
    front = r * (1.0 - 2.0 * look.hand)            # the hand's leading edge, from the centre
    palm = front + 0.7 * r
    px, py = int(cx + ux * palm), int(cy + uy * palm)
    skin = look.skin
    dark = tuple(int(0.8 * c) for c in skin)
    far = 4 * max(img.shape[:2])
    cv2.line(img, (px, py), (int(px + ux * far), int(py + uy * far)), dark, max(2, int(1.1 * r)))
    cv2.ellipse(img, (px, py), (int(0.7 * r), int(0.95 * r)), float(look.hand_angle), 0, 360,
                skin, -1)
    for k in (-0.5, 0.0, 0.5):                     # fingers curled round the fruit
        fx = int(cx + ux * (front + 0.15 * r) - uy * k * r)
        fy = int(cy + uy * (front + 0.15 * r) + ux * k * r)
        cv2.ellipse(img, (fx, fy), (int(0.2 * r), int(0.13 * r)), float(look.hand_angle), 0,
                    360, dark if k else skin, -1)


#: standard normal samples that frames with an :class:`Appearance` draw their sensor noise
#: from (a seeded slice per frame: the same seed, the same noise; far cheaper than drawing
#: a fresh frame of normals).
_NOISE: list[np.ndarray] = []


def _noise(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    n = int(np.prod(shape))
    if not _NOISE:
        _NOISE.append(np.random.default_rng(20120417).standard_normal(1 << 21,
                                                                      dtype=np.float32))
    bank = _NOISE[0]
    if n > bank.size // 2:
        return rng.standard_normal(shape, dtype=np.float32)
    start = int(rng.integers(0, bank.size - n))
    return bank[start:start + n].reshape(shape)


def _camera(img: np.ndarray, view: SceneView, rng: np.random.Generator) -> np.ndarray:
    """The light, white balance, exposure, optics and sensor of ``view.appearance``."""
    import cv2

    app = view.appearance
    assert app is not None
    s = img.shape[0] / 240.0
    gains = (app.light.gains() * float(view.lighting)).astype(np.float32)
    out = img.astype(np.float32) * gains[None, None]
    o = app.optics
    if o.blur > 0.0:
        out = cv2.GaussianBlur(out, (0, 0), o.blur * s)
    if o.motion > 0.0:
        out = cv2.filter2D(out, -1, blur_kernel(o.motion * s, o.motion_angle))
    if o.noise > 0.0:
        out += _noise(rng, out.shape) * np.float32(o.noise)
    return np.clip(out, 0, 255).astype(np.uint8)


def render(view: SceneView, size: tuple[int, int] = (320, 240)) -> np.ndarray:
    """Draw what the robot's camera sees for ``view``.

    Args:
        view: the scene as the simulator describes it.
        size: ``(width, height)`` of the frame in pixels.

    Returns:
        A ``(height, width, 3)`` uint8 BGR image.
    """
    import cv2

    w, h = int(size[0]), int(size[1])
    if w < 64 or h < 48:
        raise PerceptionError(f"frame size {size!r} is too small; use at least (64, 48)")
    rng = np.random.default_rng(view.seed)
    img = _background(h, w, view.looking_at).copy()
    u = h / 240.0
    if view.looking_at == "centre":
        if view.face_pose is not None:
            cx = w // 2 + int(rng.integers(-8, 9) * u)
            cy = int(h * 0.45)
            r = int(48 * u)
            cv2.ellipse(img, (cx, h + int(30 * u)), (int(130 * u), int(110 * u)), 0, 180, 360,
                        _SHIRT, -1)
            cv2.rectangle(img, (cx - int(22 * u), cy + r), (cx + int(22 * u), h), (120, 150, 200),
                          -1)
            _face(img, view.face_pose, cx, cy, r)
    else:
        kind = view.objects.get(view.looking_at)
        look = view.appearance.looks.get(view.looking_at) if view.appearance else None
        if kind is not None and look is not None and kind in OBJECT_KINDS:
            cx, cy = w // 2 + int(look.dx * w), h // 2 + int(look.dy * h)
            _draw_look(img, kind, cx, cy, max(4, int(38 * u * look.scale)), look)
        elif kind is not None:
            draw = OBJECT_KINDS.get(kind) or OBJECT_KINDS[f"{kind}_block"]
            cx = w // 2 + int(rng.integers(-30, 31) * u)
            cy = h // 2 + int(rng.integers(-20, 21) * u)
            draw(img, cx, cy, int(38 * u), rng)
    if view.appearance is not None:
        return _camera(img, view, rng)
    tint = 1.0 + rng.normal(0.0, 0.04, 3)
    out = img.astype(np.float32) * float(view.lighting) * tint[None, None].astype(np.float32)
    out += rng.normal(0.0, 2.5, out.shape).astype(np.float32)
    out = cv2.GaussianBlur(out, (3, 3), 0.8)
    return np.clip(out, 0, 255).astype(np.uint8)
