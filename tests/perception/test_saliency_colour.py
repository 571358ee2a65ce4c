"""Saliency, colour histograms and colour names."""

import numpy as np
import pytest

from perception.colour import colour_name, colour_summary, hsi
from perception.render import SceneView, render
from perception.saliency import SaliencyParams, most_salient, saliency_map


def test_blank_wall_is_not_salient():
    frame = render(SceneView("left", None))
    assert most_salient(frame) is None


def test_the_salient_area_is_the_object():
    frame = np.full((240, 320, 3), 150, np.uint8)
    frame[150:190, 40:80] = (30, 30, 220)
    area = most_salient(frame)
    assert area is not None
    x, y, w, h = area.box
    assert x <= 50 and x + w >= 70 and y <= 160 and y + h >= 180
    assert area.area < 0.1


def test_saliency_map_shape_is_independent_of_frame_size():
    a = saliency_map(np.zeros((240, 320, 3), np.uint8))
    b = saliency_map(np.zeros((480, 640, 3), np.uint8))
    assert a.shape == b.shape == (30, 40)


def test_min_area_rejects_a_speck():
    frame = np.full((240, 320, 3), 150, np.uint8)
    frame[100:103, 100:103] = (0, 0, 255)
    assert most_salient(frame, SaliencyParams(min_area=0.05)) is None


def test_exclusion_hides_an_area():
    frame = np.full((240, 320, 3), 150, np.uint8)
    frame[150:190, 40:80] = (30, 30, 220)
    assert most_salient(frame, exclude=[(0, 110, 130, 130)]) is None


@pytest.mark.parametrize("bgr,hue", [((0, 0, 255), 0.0), ((0, 255, 0), 120.0),
                                     ((255, 0, 0), 240.0), ((0, 255, 255), 60.0)])
def test_hsi_hue_of_primaries(bgr, hue):
    h, s, _i = hsi(np.array([bgr]))
    assert abs(h[0] - hue) < 1e-3 and abs(s[0] - 1.0) < 1e-6


def test_colour_names_cover_the_circle():
    assert colour_name(0.0) == colour_name(350.0) == "red"
    assert colour_name(30.0) == "orange" and colour_name(55.0) == "yellow"
    assert colour_name(120.0) == "green" and colour_name(None) is None


def test_summary_modes_and_grey_area():
    frame = np.zeros((10, 10, 3), np.uint8)
    frame[:] = (20, 130, 250)
    mask = np.full((10, 10), 255, np.uint8)
    s = colour_summary(frame, mask)
    assert (s.r, s.g, s.b) == (252, 132, 20) and s.name == "orange"
    frame[:] = 128
    assert colour_summary(frame, mask).name is None


@pytest.mark.parametrize("kind,name", [("apple", "red"), ("lemon", "yellow"),
                                       ("orange", "orange"), ("lime", "green"),
                                       ("blue", "blue")])
@pytest.mark.parametrize("lighting", [0.6, 1.0, 1.3])
def test_fruit_colours_named_under_varied_light(kind, name, lighting):
    from perception.pipeline import Perceiver

    for seed, place in enumerate(["left", "left_down", "right_down"]):
        frame = render(SceneView(place, None, {place: kind}, lighting, seed))
        percept = Perceiver().analyse(frame, looking_at=place)
        assert ("colour", "object", name) in percept.facts, (place, percept.facts)


def test_summary_reads_every_masked_pixel_whatever_the_mask_type():
    rng = np.random.default_rng(5)
    frame = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
    mask = np.zeros((60, 80), np.uint8)
    mask[5:9, 3:7] = 255       # two separate blobs: the bounding box holds unmasked pixels too
    mask[40:55, 60:78] = 255
    frame[40:55, 60:78] = (20, 130, 250)
    pixels = frame[mask > 0]
    expected = colour_summary(pixels[None], np.full((1, len(pixels)), 255, np.uint8))
    for m in (mask, mask > 0, (mask > 0) * 256):  # 256 would wrap to 0 as uint8
        assert colour_summary(frame, m) == expected
    assert colour_summary(frame, np.zeros_like(mask)).r == 0
