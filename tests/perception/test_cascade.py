"""perception.cascade: the compiled evaluator finds what OpenCV's CascadeClassifier finds."""

import threading
from pathlib import Path

import cv2
import numpy as np
import pytest

from perception.cascade import Cascade, group, parse_cascade
from perception.render import SceneView, render
from perception.vocabulary import POSES

_DIR = Path(cv2.data.haarcascades)
_FILES = ("haarcascade_frontalface_alt2.xml", "haarcascade_profileface.xml")


def _images() -> list[np.ndarray]:
    """Grey images with and without faces, at the sizes the face search uses and others."""
    from skimage import data

    out = []
    crops = (data.lfw_subset() * 255).round().astype(np.uint8)
    for crop in crops[::10]:  # 10 faces and 10 non-faces, enlarged and padded as in the bench
        out.append(cv2.copyMakeBorder(cv2.resize(crop, (64, 64)), 16, 16, 16, 16,
                                      cv2.BORDER_REPLICATE))
    for name in ("astronaut", "camera", "coffee", "rocket", "page", "coins"):
        img = getattr(data, name)()
        grey = img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_RGB2GRAY)
        for h in (120, 77):
            w = round(grey.shape[1] * h / grey.shape[0] * (4 / 3 if name == "camera" else 1))
            out.append(cv2.resize(grey, (w, h), interpolation=cv2.INTER_AREA))
    for pose in POSES:
        frame = render(SceneView("centre", pose, lighting=0.8, seed=3), (320, 240))
        grey = cv2.resize(cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY), (160, 120),
                          interpolation=cv2.INTER_AREA)
        out += [grey, cv2.flip(grey, 1)]
    return out


@pytest.fixture(scope="module")
def images() -> list[np.ndarray]:
    return _images()


def _opencv(classifier, img, scale, neighbours, lo, hi):
    hits = classifier.detectMultiScale(img, scale, neighbours, minSize=(lo, lo), maxSize=(hi, hi))
    return sorted(tuple(int(v) for v in hit) for hit in hits)


@pytest.mark.parametrize("name", _FILES)
@pytest.mark.slow
def test_same_raw_hits_and_faces_as_opencv(name, images):
    """Raw hits (``minNeighbors=0``) as sets and grouped faces, over random scale steps, size
    ranges (including the single-scale and between-steps cases) and crops."""
    ours, theirs = Cascade(_DIR / name), cv2.CascadeClassifier(str(_DIR / name))
    rng = np.random.default_rng(7)
    raw_hits = faces = 0
    for img in images:
        side = min(img.shape)
        y0, x0 = (int(rng.integers(0, v // 3 + 1)) for v in img.shape)
        for crop in (img, img[y0:, x0:]):
            lo = int(rng.integers(18, 40))
            v = int(rng.integers(18, 60))
            for scale, a, b in ((1.15, 20, side), (float(rng.choice([1.1, 1.2, 1.3])), lo,
                                                  int(rng.integers(lo, side + 6))),
                                (float(rng.choice([1.15, 1.3])), v, v)):
                expected = _opencv(theirs, crop, scale, 0, a, b)
                assert sorted(group(ours.raw(crop, scale, a, b), 0, crop.shape)) == expected
                raw_hits += len(expected)
                expected = _opencv(theirs, crop, scale, 3, a, b)
                assert sorted(ours.detect(crop, scale, 3, a, b)) == expected
                faces += len(expected)
    assert raw_hits > 100 and faces > 5  # the comparison saw real detections


@pytest.mark.slow
def test_bands_of_a_search_add_up_to_the_search(images):
    cascade = Cascade(_DIR / _FILES[1])
    for img in images[:8]:
        side = min(img.shape)
        whole = cascade.raw(img, 1.15, 20, side)
        parts = [hit for lo, hi in ((20, 23), (24, 40), (41, side))
                 for hit in cascade.raw(img, 1.15, 20, side, band=(lo, hi))]
        assert parts == whole


@pytest.mark.slow
def test_threads_search_at_once_with_the_same_results(images):
    cascade = Cascade(_DIR / _FILES[0])
    expected = [cascade.raw(img, 1.15, 20, min(img.shape)) for img in images]
    got: dict[int, list] = {}

    def run(k: int) -> None:
        got[k] = [cascade.raw(img, 1.15, 20, min(img.shape)) for img in images]

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert got[0] == expected and got[1] == expected


def test_too_small_an_image_has_no_hits():
    cascade = Cascade(_DIR / _FILES[0])
    assert cascade.raw(np.zeros((15, 40), np.uint8), 1.15, 20, 40) == []
    assert cascade.detect(np.full((60, 60), 128, np.uint8), 1.15, 3, 20, 60) == []


@pytest.mark.slow
def test_parse_reads_the_cascade_and_rejects_what_it_cannot_run(tmp_path):
    model = parse_cascade(_DIR / _FILES[1])
    assert (model.width, model.height) == (20, 20)
    assert len(model.stage_threshold) == 26 and model.weak[:, 0].max() == 1  # stumps
    assert parse_cascade(_DIR / _FILES[0]).weak[:, 0].max() == 2  # two-node trees
    text = (_DIR / _FILES[1]).read_text()
    tilted = tmp_path / "tilted.xml"
    tilted.write_text(text.replace("<rects>", "<tilted>1</tilted><rects>", 1))
    with pytest.raises(ValueError, match="tilted"):
        parse_cascade(tilted)
    lbp = tmp_path / "lbp.xml"
    lbp.write_text(text.replace("<featureType>HAAR</featureType>",
                                "<featureType>LBP</featureType>"))
    with pytest.raises(ValueError, match="not a boosted Haar cascade"):
        parse_cascade(lbp)


def test_without_numba_the_same_calls_run_opencv(monkeypatch, images):
    import perception.cascade as cascade_module

    monkeypatch.setattr(cascade_module, "_kernels", lambda: None)
    ours, theirs = Cascade(_DIR / _FILES[0]), cv2.CascadeClassifier(str(_DIR / _FILES[0]))
    for img in images[:6]:
        side = min(img.shape)
        assert sorted(ours.detect(img, 1.15, 3, 20, side)) == _opencv(theirs, img, 1.15, 3, 20,
                                                                       side)
        assert sorted(map(tuple, ours.raw(img, 1.15, 20, side))) == _opencv(theirs, img, 1.15, 0,
                                                                             20, side)
        assert ours.raw(img, 1.15, 20, side, band=(41, 45)) == []  # no step of 1.15 there


def test_bad_input_is_refused():
    cascade = Cascade(_DIR / _FILES[0])
    with pytest.raises(ValueError, match="2-D uint8"):
        cascade.raw(np.zeros((40, 40, 3), np.uint8), 1.15, 20, 40)
    with pytest.raises(ValueError, match="2-D uint8"):
        cascade.detect(np.zeros((40, 40), np.float32), 1.15, 3, 20, 40)
    with pytest.raises(ValueError, match="above 1"):
        cascade.raw(np.zeros((40, 40), np.uint8), 1.0, 20, 40)
