"""relrl perceive."""

import cv2

from perception.render import SceneView, render
from relrl.cli import main


def test_perceive_image_prints_facts_and_annotates(tmp_path, capsys):
    img = tmp_path / "face.png"
    cv2.imwrite(str(img), render(SceneView("centre", "right_1", seed=1)))
    out = tmp_path / "out.png"
    assert main(["perceive", str(img), "--annotate", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[:2] == ["see(face).", "pose(face, right_1)."]
    assert cv2.imread(str(out)).shape == (240, 320, 3)


def test_perceive_camera_frames(capsys):
    url = "synthetic://?looking_at=right&objects=right:lemon"
    assert main(["perceive", "--camera", url, "--frames", "2", "--looking-at", "right"]) == 0
    out = capsys.readouterr().out
    assert out.count("colour(object, yellow).") == 2 and "% frame 1" in out


def test_errors_are_one_line_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.png"
    bad.write_text("x")
    for argv in (["perceive", str(tmp_path / "missing.png")], ["perceive", str(bad)],
                 ["perceive", "--camera", "cam://nope"], ["perceive"],
                 ["perceive", "--camera", "cam://97"],
                 ["perceive", "--camera", "ftp://x"],
                 ["perceive", "--camera", "synthetic://", "--threads", "0"]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Traceback" not in err, err


def test_perceive_with_two_threads_prints_the_same(tmp_path, capsys):
    img = tmp_path / "profile.png"
    cv2.imwrite(str(img), render(SceneView("centre", "left_2", seed=2)))
    outs = []
    for threads in ("1", "2"):
        assert main(["perceive", str(img), "--threads", threads]) == 0
        outs.append(capsys.readouterr().out)
    assert outs[0] == outs[1] and "pose(face, left_2)." in outs[0]
