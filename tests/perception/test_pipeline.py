"""perceive(): frames to facts; format_fact; annotate."""

import numpy as np
import pytest

from perception import Perceiver, format_fact, perceive
from perception.errors import PerceptionError
from perception.pipeline import annotate
from perception.render import SceneView, render


def test_facts_for_the_caregiver():
    facts = perceive(render(SceneView("centre", "left_1", seed=2)))
    assert facts[:3] == [("see", "face"), ("pose", "face", "left_1"), facts[2]]
    assert facts[2][0] == "pan" and facts[2][2] < -15
    assert ("see", "object") not in facts  # the caregiver's body is not an object


@pytest.mark.parametrize("pose", ["left_2", "right_2", "down"])
def test_the_caregivers_head_is_not_an_object(pose):
    facts = perceive(render(SceneView("centre", pose, seed=4)))
    assert ("pose", "face", pose) in facts and ("see", "object") not in facts


def test_facts_for_a_fruit_where_the_head_looks():
    frame = render(SceneView("left_down", None, {"left_down": "apple"}))
    assert perceive(frame, looking_at="left_down") == [
        ("see", "object"), ("colour", "object", "red"), ("at", "object", "left_down")]


def test_place_from_the_image_without_head_state():
    frame = np.full((240, 320, 3), 160, np.uint8)
    frame[170:210, 20:60] = (40, 215, 235)
    assert ("at", "object", "left_down") in perceive(frame)


def test_nothing_seen_in_an_empty_place():
    assert perceive(render(SceneView("right", None))) == []


def test_state_keeps_tracking():
    p = Perceiver()
    for k in range(3):
        perceive(render(SceneView("centre", "frontal", seed=k)), state=p)
    assert p.tracker.full_searches == 1


@pytest.mark.parametrize("bad", [np.zeros((10, 10)), np.zeros((10, 10, 3)), "frame"])
def test_bad_frames_are_user_errors(bad):
    with pytest.raises(PerceptionError):
        perceive(bad)


def test_bad_place_is_a_user_error():
    with pytest.raises(PerceptionError, match="unknown place"):
        perceive(np.zeros((48, 64, 3), np.uint8), looking_at="up")


@pytest.mark.parametrize("fact,text", [
    (("see", "face"), "see(face)."),
    (("pan", "face", -23.5), "pan(face, -23.5)."),
    (("colour", "object", "Red Apple"), "colour(object, 'Red Apple')."),
    (("at", "object", ["a", 1]), "at(object, [a, 1])."),
    ("done", "done."),
    (("it's",), "'it\\'s'."),
])
def test_format_fact(fact, text):
    assert format_fact(fact) == text


@pytest.mark.parametrize("bad", [None, {"a": 1}, float("nan"), True, ()])
def test_format_fact_rejects_non_terms(bad):
    with pytest.raises(TypeError):
        format_fact(bad)


def test_annotate_draws_without_changing_the_frame():
    frame = render(SceneView("centre", "frontal"))
    before = frame.copy()
    out = annotate(frame, Perceiver().analyse(frame))
    assert np.array_equal(frame, before) and not np.array_equal(out, frame)


@pytest.mark.slow
def test_the_speed_harness_runs_from_the_source_tree():
    import perception
    from bench.perception_speed import bench

    out = bench(frames=12, faces=False)
    assert out["fps_320x240"] > 0 and out["fps_640x480_cold"] > 0
    assert not hasattr(perception, "bench")  # the installed package holds no harness


@pytest.mark.slow
def test_two_threads_give_the_same_facts():
    from bench.perception_speed import _photos

    frames = [render(SceneView("centre", pose, seed=6)) for pose in ("frontal", "left_2",
                                                                      "right_2")]
    frames += [render(SceneView("left_down", None, {"left_down": "lemon"})), *_photos((320, 240))]
    one = Perceiver()
    with Perceiver(threads=2) as two:
        for cold in (False, True):
            for frame in frames:
                if cold:
                    one.reset()
                    two.reset()
                assert two.perceive(frame) == one.perceive(frame)
    assert two.pool is None
    two.close()  # safe twice


@pytest.mark.parametrize("bad", [0, -1, 1.5, "2", True])
def test_bad_thread_counts_are_user_errors(bad):
    with pytest.raises(PerceptionError, match="threads"):
        Perceiver(threads=bad)
