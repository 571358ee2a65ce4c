"""Faces and head pose on real photographs and rendered faces."""

import cv2
import numpy as np
import pytest

from bench.perception_speed import lfw_figures
from perception.faces import FaceTracker, detect_face
from perception.render import SceneView, render
from perception.vocabulary import POSES


def test_astronaut_face_is_found_frontal(astronaut_bgr):
    face = detect_face(astronaut_bgr)
    assert face is not None and face.pose == "frontal"
    x, y, w, h = face.box
    assert 150 < x + w / 2 < 290 and 60 < y + h / 2 < 190  # her face, not the flag


def test_mirrored_astronaut_is_still_frontal(astronaut_bgr):
    face = detect_face(cv2.flip(astronaut_bgr, 1))
    assert face is not None and face.pose == "frontal"


def test_no_face_in_a_blank_or_noisy_frame():
    rng = np.random.default_rng(0)
    assert detect_face(np.full((240, 320, 3), 128, np.uint8)) is None
    assert detect_face(rng.integers(0, 256, (240, 320, 3), dtype=np.uint8)) is None


@pytest.mark.slow
def test_lfw_recall_and_no_false_detection():
    # the figures of the full search today (98 / 100 faces, 0 on 100 non-faces): a faster
    # search must not find fewer faces or any non-face
    figures = lfw_figures()
    assert figures["faces_found"] >= 98
    assert figures["false_detections"] == 0


@pytest.mark.parametrize("pose", POSES)
@pytest.mark.parametrize("lighting", [0.6, 1.0, 1.25])
def test_rendered_pose_is_recognised(pose, lighting):
    for size in ((320, 240), (640, 480)):
        frame = render(SceneView("centre", pose, lighting=lighting, seed=7), size)
        face = detect_face(frame)
        assert face is not None, (pose, lighting, size)
        assert face.pose == pose, (pose, lighting, size, face)


@pytest.mark.parametrize("pose", ["left_1", "left_2"])
def test_mirrored_left_pose_reads_as_right(pose):
    frame = render(SceneView("centre", pose, seed=3))
    face = detect_face(cv2.flip(frame, 1))
    assert face is not None and face.pose == pose.replace("left", "right")


def test_pan_sign_follows_the_nose():
    left = detect_face(render(SceneView("centre", "left_1", seed=1)))
    right = detect_face(render(SceneView("centre", "right_1", seed=1)))
    front = detect_face(render(SceneView("centre", "frontal", seed=1)))
    assert left.pan < -15 < abs(front.pan) - 15 < 15 < right.pan
    assert detect_face(render(SceneView("centre", "left_2", seed=1))).pan < left.pan


@pytest.mark.slow
def test_tracker_searches_near_the_last_face():
    tracker = FaceTracker()
    frames = [render(SceneView("centre", p, seed=k))
              for k, p in enumerate(["frontal"] * 5 + ["left_1"] * 5 + ["left_2"] * 5)]
    poses = [tracker.detect(f).pose for f in frames]
    assert poses == ["frontal"] * 5 + ["left_1"] * 5 + ["left_2"] * 5
    assert tracker.full_searches <= 3


def test_tracker_forgets_a_lost_face():
    tracker = FaceTracker()
    assert tracker.detect(render(SceneView("centre", "frontal"))) is not None
    assert tracker.detect(render(SceneView("left", None))) is None
    assert tracker.last is None


def _lfw_frames(step: int) -> list[np.ndarray]:
    from skimage import data

    crops = (data.lfw_subset() * 255).round().astype(np.uint8)[::step]
    return [cv2.copyMakeBorder(cv2.resize(c, (64, 64)), 16, 16, 16, 16, cv2.BORDER_REPLICATE)
            for c in crops]


@pytest.mark.slow
def test_pooled_full_search_finds_the_same_faces(astronaut_bgr):
    from concurrent.futures import ThreadPoolExecutor

    from bench.perception_speed import _photos

    frames = [render(SceneView("centre", pose, lighting=light, seed=5), size)
              for pose in POSES for light in (0.6, 1.25) for size in ((320, 240), (640, 480))]
    frames += [*_photos((320, 240)), *_photos((640, 480)), astronaut_bgr, *_lfw_frames(5)]
    serial = FaceTracker()
    with ThreadPoolExecutor(2) as pool:
        pooled = FaceTracker(pool=pool)
        for frame in frames:
            serial.reset()
            pooled.reset()
            assert pooled.detect(frame) == serial.detect(frame)
    # a found face cancels the later cascades' tasks, and the next search still works
    assert pooled.full_searches == serial.full_searches == len(frames)


def test_bands_cover_the_sizes_once():
    from perception.faces import _bands

    assert _bands(20, 120) == [(20, 20), (21, 23), (24, 30), (31, 46), (47, 120)]
    assert _bands(25, 40) == [(25, 30), (31, 40)]
    assert _bands(20, 20) == [(20, 20)]
    assert _bands(20, 16) == []  # a frame too small for any face
