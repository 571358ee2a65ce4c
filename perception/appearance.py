"""How a camera sees fruit in a real room: seeded, bounded appearance variation for the renderer.

:func:`perception.render.render` draws what a :class:`perception.render.SceneView` describes;
with an :class:`Appearance` attached it draws it the way a webcam in a lit room would, so that
perception (saliency, colour, ART2) errs as it would on a camera's frames. Every parameter is
drawn from a seeded generator within the bounds of a :class:`Variation`:

* **Light and white balance** (:class:`Light`): the room's light has a colour temperature
  (2,800 K incandescent to 6,500 K overcast daylight); its cast follows Planck's law seen
  through broad camera channels (and the sRGB encoding); the camera's automatic white balance
  removes only part of it (a fraction drawn per presentation: white balance is pulled by what
  fills the view); auto exposure leaves a brightness gain.
* **Optics and sensor** (:class:`Optics`): Gaussian defocus, motion blur in the frames where
  the head has just turned, sensor noise.
* **The fruit** (:class:`FruitLook`): its shade (hue, saturation, value drawn from the range of
  real fruit of that kind), a patch of a second shade (an apple's yellow streaks, an orange's
  green skin, a ripening lime's yellow), its shape (aspect, lobes, orientation), size and
  position in the view, a specular highlight, and partial occlusion by the caregiver's hand.

A lemon drawn yellow-green under warm light with little white balance reaches the hue of an
orange; an orange under daylight reaches a lemon's. The bounds are physical, not chosen for an
outcome: see ``docs/perception.md`` for the values and why.

The variation of one time unit is split by how fast it changes: :meth:`Variation.session_light`
once per session (the room), :meth:`Variation.fruit` and :meth:`Variation.light` once per
presentation (which fruit, how it is held, where white balance settles), :meth:`Variation.optics`
every frame.
"""

from __future__ import annotations

import colorsys
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

import numpy as np

from perception.errors import PerceptionError

__all__ = ["FRUIT_SHADES", "Appearance", "FruitLook", "Light", "Optics", "Shade", "Variation",
           "illuminant_gains"]

_H, _C, _K = 6.62607e-34, 2.99792e8, 1.380649e-23
_LAMBDA = np.linspace(380e-9, 720e-9, 171)
#: broad camera channel sensitivities (B, G, R): centre and spread of each, in metres.
_CHANNELS = ((450e-9, 25e-9), (540e-9, 35e-9), (605e-9, 30e-9))
_SENS = np.array([np.exp(-0.5 * ((_LAMBDA - m) / s) ** 2) for m, s in _CHANNELS])
_REFERENCE_K = 6500.0


def _planck(t: float) -> np.ndarray:
    x = _H * _C / (_LAMBDA * _K * t)
    return _SENS @ (_LAMBDA ** -5 / np.expm1(x))


def illuminant_gains(temperature: float) -> np.ndarray:
    """Per-channel (B, G, R) gains of a black body at ``temperature`` kelvin relative to
    6,500 K, as they act on sRGB-encoded pixel values (green kept at 1)."""
    if not 1000.0 <= temperature <= 20000.0:
        raise PerceptionError(f"colour temperature {temperature!r} K is out of range "
                              "(1000..20000)")
    return _gains(float(temperature)).copy()


@functools.lru_cache(maxsize=64)
def _gains(temperature: float) -> np.ndarray:
    lin = _planck(temperature) / _planck(_REFERENCE_K)
    lin = lin / lin[1]
    return lin ** (1.0 / 2.2)


@dataclass(frozen=True)
class Light:
    """The light a frame is taken under.

    Attributes:
        temperature: colour temperature of the room's light (kelvin).
        white_balance: the fraction of the light's cast the camera's white balance removes
            (1: perfect, 0: none), in log-gain space.
        exposure: brightness gain left by auto exposure.
    """

    temperature: float = _REFERENCE_K
    white_balance: float = 1.0
    exposure: float = 1.0

    def gains(self) -> np.ndarray:
        """(B, G, R) multipliers of the pixel values, exposure included."""
        cast = illuminant_gains(self.temperature) ** (1.0 - self.white_balance)
        return cast * self.exposure


@dataclass(frozen=True)
class Optics:
    """Lens and sensor of one frame.

    Attributes:
        blur: Gaussian defocus, sigma in pixels of a 240-row frame.
        motion: motion-blur length in pixels of a 240-row frame (0: the head is still).
        motion_angle: direction of the motion blur in degrees.
        noise: sensor noise, standard deviation in 8-bit levels.
    """

    blur: float = 0.8
    motion: float = 0.0
    motion_angle: float = 0.0
    noise: float = 2.5


@dataclass(frozen=True)
class Shade:
    """The colours real fruit of one kind come in (HSV: hue in degrees, the rest 0..1).

    Attributes:
        hue, saturation, value: ranges of the main colour.
        patch_hue: range of the hue of a second colour on part of the skin.
        patch: range of the fraction of the skin the second colour covers.
        aspect: range of width / height.
        lumps: range of the outline's irregularity (fraction of the radius).
    """

    hue: tuple[float, float]
    saturation: tuple[float, float]
    value: tuple[float, float]
    patch_hue: tuple[float, float]
    patch: tuple[float, float]
    aspect: tuple[float, float] = (0.92, 1.08)
    lumps: tuple[float, float] = (0.0, 0.05)


#: shades of real fruit: red to yellow-streaked apples, orange to green-skinned oranges (the
#: Brazilian *laranja pera* is often green), dark to ripening yellow-green limes (the paper's
#: green *limao*), yellow to green-tipped lemons.
FRUIT_SHADES: dict[str, Shade] = {
    "apple": Shade((-12.0, 10.0), (0.55, 0.9), (0.5, 0.85), (35.0, 70.0), (0.0, 0.35)),
    "orange": Shade((22.0, 38.0), (0.7, 0.95), (0.75, 0.98), (45.0, 80.0), (0.0, 0.3)),
    "lime": Shade((72.0, 110.0), (0.45, 0.85), (0.45, 0.8), (52.0, 68.0), (0.0, 0.35)),
    "lemon": Shade((46.0, 60.0), (0.6, 0.9), (0.75, 0.98), (65.0, 90.0), (0.0, 0.2),
                   aspect=(1.2, 1.45)),
}


@dataclass(frozen=True)
class FruitLook:
    """One fruit as it is held in front of the camera during one presentation.

    Attributes:
        colour: main colour, BGR 0..255.
        patch_colour: second colour, BGR 0..255.
        patch: fraction of the skin in the second colour.
        aspect: width / height.
        lumps: outline irregularity (fraction of the radius).
        lobes: number of bumps of the outline.
        angle: orientation of the long axis, degrees.
        scale: size relative to the standard fruit (radius 38 pixels of a 240-row frame).
        dx, dy: centre offset from the middle of the view, fractions of width and height.
        highlight: strength of the specular highlight (0..1).
        hand: how far the caregiver's hand reaches into the fruit, as a fraction of its
            diameter (0: not occluded).
        hand_angle: the side the hand comes from, degrees (90: from below).
        skin: the hand's colour, BGR.
        texture: seed of the small random parts (patch layout, skin pores, outline phase).
    """

    colour: tuple[int, int, int]
    patch_colour: tuple[int, int, int]
    patch: float = 0.0
    aspect: float = 1.0
    lumps: float = 0.0
    lobes: int = 5
    angle: float = 0.0
    scale: float = 1.0
    dx: float = 0.0
    dy: float = 0.0
    highlight: float = 0.5
    hand: float = 0.0
    hand_angle: float = 90.0
    skin: tuple[int, int, int] = (120, 152, 200)
    texture: int = 0


@dataclass(frozen=True)
class Appearance:
    """How one frame is seen: the light, the optics, and the look of each object in view.

    Attributes:
        light: the light and the camera's response to it.
        optics: blur and noise.
        looks: place -> :class:`FruitLook` of the object there (objects without one are drawn
            in their standard look).
    """

    light: Light = field(default_factory=Light)
    optics: Optics = field(default_factory=Optics)
    looks: Mapping[str, FruitLook] = field(default_factory=dict)


def _hsv_bgr(h: float, s: float, v: float) -> tuple[int, int, int]:
    r, g, b = colorsys.hsv_to_rgb((h % 360.0) / 360.0, s, v)
    return int(round(255 * b)), int(round(255 * g)), int(round(255 * r))


def _u(rng: np.random.Generator, bounds: tuple[float, float]) -> float:
    lo, hi = bounds
    return float(rng.uniform(lo, hi)) if hi > lo else float(lo)


@dataclass(frozen=True)
class Variation:
    """Bounds of the appearance variation (every range is ``(low, high)``, inclusive).

    Attributes:
        temperature: the room's colour temperature, kelvin, drawn per session.
        drift: change of the temperature between presentations, kelvin (+-).
        white_balance: fraction of the cast the camera's white balance removes.
        exposure: brightness gain after auto exposure, drawn per frame.
        blur: defocus sigma, pixels of a 240-row frame.
        motion: motion-blur length when the head has just turned, pixels.
        noise: sensor noise sd, 8-bit levels.
        scale: fruit size relative to the standard fruit.
        offset: largest centre offset from the middle of the view, (fraction of width,
            fraction of height).
        hand_rate: probability that the caregiver's hand covers part of the fruit.
        hand: how far the hand reaches into the fruit, fraction of its diameter.
        shades: kind -> :class:`Shade`.
    """

    temperature: tuple[float, float] = (2800.0, 6500.0)
    drift: float = 150.0
    white_balance: tuple[float, float] = (0.5, 0.95)
    exposure: tuple[float, float] = (0.8, 1.2)
    blur: tuple[float, float] = (0.3, 1.3)
    motion: tuple[float, float] = (2.0, 8.0)
    noise: tuple[float, float] = (1.5, 5.0)
    scale: tuple[float, float] = (0.7, 1.3)
    offset: tuple[float, float] = (0.18, 0.15)
    hand_rate: float = 0.5
    hand: tuple[float, float] = (0.05, 0.35)
    shades: Mapping[str, Shade] = field(default_factory=lambda: dict(FRUIT_SHADES))

    def __post_init__(self) -> None:
        limits = {"temperature": (1000.0, 20000.0), "white_balance": (0.0, 1.0),
                  "exposure": (0.05, 3.0), "blur": (0.0, 5.0), "motion": (0.0, 30.0),
                  "noise": (0.0, 40.0), "scale": (0.3, 2.0), "offset": (0.0, 0.3),
                  "hand": (0.0, 0.6)}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in limits:
                lo, hi = limits[f.name]
                if (len(value) != 2 or not all(isinstance(x, (int, float)) for x in value)
                        or not all(lo <= x <= hi for x in value)
                        or (f.name != "offset" and value[0] > value[1])):
                    raise PerceptionError(f"variation {f.name} = {value!r}: use two numbers "
                                          f"low <= high within {lo}..{hi}")
        if not 0.0 <= self.hand_rate <= 1.0 or not 0.0 <= self.drift <= 2000.0:
            raise PerceptionError("variation hand_rate must be within 0..1 and drift within "
                                  "0..2000 K")

    # ---- drawing parameters from a seeded generator --------------------------------------

    def session_light(self, rng: np.random.Generator) -> float:
        """The room's colour temperature for a whole session."""
        return _u(rng, self.temperature)

    def light(self, rng: np.random.Generator, session_temperature: float) -> Light:
        """The light of one presentation: the room's temperature with a little drift, and
        where the camera's white balance settles (its exposure is drawn per frame)."""
        lo, hi = self.temperature
        t = float(np.clip(session_temperature + rng.uniform(-self.drift, self.drift), lo, hi))
        return Light(t, _u(rng, self.white_balance), 1.0)

    def exposed(self, rng: np.random.Generator, light: Light) -> Light:
        """``light`` with this frame's auto-exposure gain."""
        return Light(light.temperature, light.white_balance, _u(rng, self.exposure))

    def optics(self, rng: np.random.Generator, moving: bool = False) -> Optics:
        """The optics of one frame; ``moving`` when the head turned in this time unit."""
        motion = _u(rng, self.motion) if moving else 0.0
        return Optics(_u(rng, self.blur), motion, float(rng.uniform(-20.0, 20.0)),
                      _u(rng, self.noise))

    def fruit(self, rng: np.random.Generator, kind: str) -> FruitLook:
        """One fruit of ``kind`` as it is held during one presentation."""
        shade = self.shades.get(kind)
        if shade is None:
            raise PerceptionError(f"no shades for {kind!r}; known: {sorted(self.shades)}")
        colour = _hsv_bgr(_u(rng, shade.hue), _u(rng, shade.saturation), _u(rng, shade.value))
        patch = _hsv_bgr(_u(rng, shade.patch_hue), _u(rng, shade.saturation),
                         _u(rng, shade.value))
        hand = _u(rng, self.hand) if rng.random() < self.hand_rate else 0.0
        skin = _hsv_bgr(_u(rng, (14.0, 28.0)), _u(rng, (0.25, 0.5)), _u(rng, (0.55, 0.9)))
        ox, oy = self.offset
        return FruitLook(colour, patch, _u(rng, shade.patch), _u(rng, shade.aspect),
                         _u(rng, shade.lumps), int(rng.integers(3, 7)),
                         float(rng.uniform(-30.0, 30.0)), _u(rng, self.scale),
                         float(rng.uniform(-ox, ox)), float(rng.uniform(-oy, oy)),
                         float(rng.uniform(0.2, 0.8)), hand, float(rng.uniform(30.0, 150.0)),
                         skin, int(rng.integers(2**31)))


#: no variation at all: the light at the reference temperature, no blur, no noise.
NONE = Appearance(Light(), Optics(0.0, 0.0, 0.0, 0.0))


def blur_kernel(length: float, angle: float) -> np.ndarray:
    """A normalised line kernel for motion blur of ``length`` pixels at ``angle`` degrees
    (to the nearest half pixel and degree)."""
    return _line_kernel(round(2.0 * float(length)) / 2.0, float(round(angle))).copy()


@functools.lru_cache(maxsize=512)
def _line_kernel(length: float, angle: float) -> np.ndarray:
    size = max(1, math.ceil(length)) | 1
    c = size // 2
    a = math.radians(angle)
    s = np.linspace(-length / 2.0, length / 2.0, 2 * size + 1)
    k = np.zeros((size, size), np.float32)
    k[np.rint(c + s * math.sin(a)).astype(int), np.rint(c + s * math.cos(a)).astype(int)] = 1.0
    return k / k.sum()
