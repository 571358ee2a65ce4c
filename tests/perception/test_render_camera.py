"""The synthetic renderer and the camera sources."""

import cv2
import numpy as np
import pytest

from perception.camera import SOURCES, SyntheticCamera, open_camera
from perception.errors import CameraError, ImageError, PerceptionError
from perception.render import SceneView, render


@pytest.mark.slow
def test_render_is_deterministic_and_sized():
    v = SceneView("left", None, {"left": "apple"}, 0.8, seed=4)
    a, b = render(v, (640, 480)), render(v, (640, 480))
    assert a.shape == (480, 640, 3) and a.dtype == np.uint8 and np.array_equal(a, b)
    assert not np.array_equal(a, render(SceneView("left", None, {"left": "apple"}, 0.8, 5),
                                        (640, 480)))


def test_lighting_changes_brightness():
    dim = render(SceneView("left", None, lighting=0.5)).mean()
    bright = render(SceneView("left", None, lighting=1.2)).mean()
    assert dim < 0.6 * bright


def test_objects_show_only_where_the_head_looks():
    scene = {"left": "lemon"}
    assert render(SceneView("left", None, scene)).std() > render(SceneView("right", None,
                                                                           scene)).std() + 10


@pytest.mark.parametrize("kwargs,match", [
    ({"looking_at": "up"}, "unknown place"),
    ({"looking_at": "centre", "face_pose": "sideways"}, "unknown face pose"),
    ({"looking_at": "left", "objects": {"centre": "apple"}}, "cannot be at"),
    ({"looking_at": "left", "objects": {"left": "banana"}}, "unknown object"),
    ({"looking_at": "left", "lighting": 9.0}, "lighting"),
])
def test_bad_views_are_user_errors(kwargs, match):
    with pytest.raises(PerceptionError, match=match):
        SceneView(**kwargs)


def test_synthetic_url_options():
    with open_camera("synthetic://?looking_at=left_down&objects=left_down:apple&size=160x120"
                     "&seed=2") as cam:
        frame = cam.read()
        assert frame.shape == (120, 160, 3)
        cam.set_view(SceneView("centre", "frontal"))
        assert cam.read().shape == (120, 160, 3)
    assert cam.read() is None
    cam.close()  # twice is fine


@pytest.mark.parametrize("url,match", [
    ("synthetic://?colour=red", "unknown synthetic"),
    ("synthetic://?size=big", "bad synthetic"),
    ("ftp://x", "unknown camera scheme"),
    ("cam://abc", "bad webcam index"),
    ("/no/such/video.mp4", "no such video"),
    ("dir:///no/such/folder", "no such folder"),
])
def test_bad_sources(url, match):
    with pytest.raises(CameraError, match=match):
        open_camera(url)


def test_folder_and_image_sources(tmp_path):
    for k in range(3):
        cv2.imwrite(str(tmp_path / f"f{k}.png"), np.full((20, 30, 3), 40 * k, np.uint8))
    (tmp_path / "notes.txt").write_text("not an image")
    with open_camera(str(tmp_path)) as cam:
        frames = list(cam)
    assert [int(f[0, 0, 0]) for f in frames] == [0, 40, 80]
    with open_camera(str(tmp_path / "f1.png")) as cam:
        assert len(list(cam)) == 1
    (tmp_path / "bad.png").write_text("not png")
    with pytest.raises(ImageError, match="cannot decode"):
        open_camera(str(tmp_path / "bad.png"))


def test_video_file_source(tmp_path):
    path = str(tmp_path / "clip.avi")
    out = cv2.VideoWriter(path, cv2.VideoWriter_fourcc(*"MJPG"), 10, (64, 48))
    for k in range(4):
        out.write(np.full((48, 64, 3), 60 * k, np.uint8))
    out.release()
    with open_camera(path) as cam:
        assert len(list(cam)) == 4


def test_registry_has_every_kind():
    assert {"cam", "file", "dir", "image", "synthetic"} <= set(SOURCES)
    assert isinstance(open_camera("synthetic://"), SyntheticCamera)


@pytest.mark.slow
def test_render_is_the_function_after_importing_sceneview() -> None:
    """Regression: importing SceneView first bound perception.render to the submodule."""
    import subprocess
    import sys

    code = ("from perception import SceneView, render; import perception; "
            "assert callable(render) and not hasattr(render, '__path__'), render; "
            "assert perception.render is render; print('ok')")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stdout.strip() == "ok", proc.stderr
