"""Appearance variation: seeded, bounded, physically ordered, and errs as a camera would."""

from __future__ import annotations

import numpy as np
import pytest

from perception.appearance import (
    FRUIT_SHADES,
    Appearance,
    FruitLook,
    Light,
    Variation,
    blur_kernel,
    illuminant_gains,
)
from perception.errors import PerceptionError
from perception.render import SceneView, render


def test_illuminant_gains_follow_the_colour_temperature() -> None:
    assert np.allclose(illuminant_gains(6500.0), 1.0)
    warm, neutral = illuminant_gains(2800.0), illuminant_gains(4500.0)
    b, g, r = warm
    assert r > 1.0 > b and g == pytest.approx(1.0)
    assert warm[2] > neutral[2] > 1.0 and warm[0] < neutral[0] < 1.0
    with pytest.raises(PerceptionError, match="out of range"):
        illuminant_gains(100.0)


def test_white_balance_removes_the_cast() -> None:
    cast = Light(3000.0, 0.0, 1.0).gains()
    half = Light(3000.0, 0.5, 1.0).gains()
    assert np.allclose(Light(3000.0, 1.0, 1.0).gains(), 1.0)
    assert cast[2] > half[2] > 1.0 and np.allclose(half ** 2, cast)
    assert np.allclose(Light(6500.0, 0.0, 0.8).gains(), 0.8)


def test_draws_are_seeded() -> None:
    var = Variation()

    def draw(seed: int) -> tuple:
        rng = np.random.default_rng(seed)
        room = var.session_light(rng)
        return room, var.light(rng, room), var.optics(rng, True), var.fruit(rng, "apple")

    assert draw(3) == draw(3)
    assert draw(3) != draw(4)


def test_draws_stay_within_their_bounds() -> None:
    var = Variation()
    rng = np.random.default_rng(0)
    lo_t, hi_t = var.temperature
    hands = 0
    for k in range(400):
        kind = sorted(FRUIT_SHADES)[k % len(FRUIT_SHADES)]
        room = var.session_light(rng)
        light = var.exposed(rng, var.light(rng, room))
        optics = var.optics(rng, moving=bool(k % 2))
        look = var.fruit(rng, kind)
        assert lo_t <= room <= hi_t and lo_t <= light.temperature <= hi_t
        assert abs(light.temperature - room) <= var.drift + 1e-9
        assert var.white_balance[0] <= light.white_balance <= var.white_balance[1]
        assert var.exposure[0] <= light.exposure <= var.exposure[1]
        assert var.blur[0] <= optics.blur <= var.blur[1]
        assert var.noise[0] <= optics.noise <= var.noise[1]
        assert (optics.motion == 0.0) if k % 2 == 0 else \
            (var.motion[0] <= optics.motion <= var.motion[1])
        assert var.scale[0] <= look.scale <= var.scale[1]
        assert abs(look.dx) <= var.offset[0] and abs(look.dy) <= var.offset[1]
        shade = FRUIT_SHADES[kind]
        assert shade.aspect[0] <= look.aspect <= shade.aspect[1]
        assert shade.patch[0] <= look.patch <= shade.patch[1]
        assert look.hand == 0.0 or var.hand[0] <= look.hand <= var.hand[1]
        hands += look.hand > 0
        assert all(0 <= c <= 255 for c in look.colour + look.patch_colour + look.skin)
    assert 120 < hands < 280   # hand_rate 0.5


@pytest.mark.parametrize("kwargs,match", [
    ({"temperature": (6000.0, 3000.0)}, "temperature"),
    ({"white_balance": (0.5, 1.5)}, "white_balance"),
    ({"noise": (1.0,)}, "noise"),
    ({"hand_rate": 2.0}, "hand_rate"),
])
def test_bad_variation_is_a_perception_error(kwargs, match) -> None:
    with pytest.raises(PerceptionError, match=match):
        Variation(**kwargs)


def test_unknown_kind_has_no_shades() -> None:
    with pytest.raises(PerceptionError, match="no shades"):
        Variation().fruit(np.random.default_rng(0), "banana")


def test_motion_kernel_is_normalised() -> None:
    k = blur_kernel(6.0, 10.0)
    assert k.sum() == pytest.approx(1.0) and (k > 0).sum() >= 5


def test_render_with_appearance_is_deterministic_and_changes_the_frame() -> None:
    var = Variation()
    rng = np.random.default_rng(1)
    app = Appearance(var.exposed(rng, var.light(rng, 3000.0)), var.optics(rng, True),
                     {"left": var.fruit(rng, "orange")})
    view = SceneView("left", None, {"left": "orange"}, 1.0, 5, app)
    a, b = render(view), render(view)
    assert np.array_equal(a, b)
    plain = render(SceneView("left", None, {"left": "orange"}, 1.0, 5))
    assert np.abs(a.astype(int) - plain.astype(int)).mean() > 5
    # the warm room with little white balance makes the wall reddish
    wall = a[:20, :20].reshape(-1, 3).mean(axis=0)
    assert wall[2] > wall[0] + 5


def test_the_hand_covers_part_of_the_fruit() -> None:
    base = dict(colour=(40, 40, 205), patch_colour=(40, 40, 205), highlight=0.0)
    free = Appearance(looks={"left": FruitLook(**base)})
    held = Appearance(looks={"left": FruitLook(**base, hand=0.3, hand_angle=90.0)})
    frames = [render(SceneView("left", None, {"left": "apple"}, 1.0, 0, app)).astype(int)
              for app in (free, held)]
    red = [((f[..., 2] - f[..., 1]) > 80).sum() for f in frames]
    assert red[1] < 0.92 * red[0]


@pytest.mark.slow
def test_faces_survive_the_camera() -> None:
    from perception.pipeline import Perceiver
    from perception.vocabulary import POSES

    var = Variation()
    rng = np.random.default_rng(5)
    right = 0
    for k in range(24):
        pose = POSES[k % len(POSES)]
        app = Appearance(var.exposed(rng, var.light(rng, var.session_light(rng))),
                         var.optics(rng, moving=k % 3 == 0))
        face = Perceiver().analyse(render(SceneView("centre", pose, {}, 1.0, k, app)),
                                   looking_at="centre").face
        right += face is not None and face.pose == pose
    assert right >= 22


@pytest.mark.slow
def test_art2_errs_with_variation_and_not_without() -> None:
    from perception.fruits import table1

    varied = table1(3, 45, seed=0, variation=Variation())
    plain = table1(3, 45, seed=0)
    wrong = sum(r["error"] + r["incorrect_guess"] for r in varied["runs"])
    assert wrong > 0, varied["confusion"]
    assert sum(r["error"] + r["incorrect_guess"] for r in plain["runs"]) == 0
    assert varied["rates"]["success"][1] > 0.0          # it varies across executions
    assert 50.0 < varied["rates"]["success"][0] < 95.0  # but a camera still mostly works
    confused = sum(n for fruit, row in varied["confusion"].items() for said, n in row.items()
                   if said not in (fruit, "nothing"))
    assert confused == wrong
