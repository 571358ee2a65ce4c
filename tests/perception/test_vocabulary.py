"""One vocabulary: every package uses the same definitions, and each world's declared percepts
are exactly what the world produces."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import perception.vocabulary as percepts
from perception.vocabulary import (
    ANY,
    COLOURS,
    GAZE_POSE,
    HUES,
    OBJECT_PLACES,
    PLACES,
    POSES,
    SIS_POSES,
    WORLDS,
    world,
)
from tests.conftest import ROOT


def test_every_package_uses_the_one_definition() -> None:
    import head
    import perception
    import relrl.episodes.script
    import relrl.episodes.world
    import relrl.sim.places
    import relrl.sim.sis

    assert head.DIRECTIONS is PLACES
    assert perception.PLACES is PLACES and perception.POSES is POSES
    assert perception.COLOURS is COLOURS and perception.HUES is HUES and tuple(HUES) == COLOURS
    assert relrl.sim.places.PLACES is PLACES and relrl.sim.places.TOY_PLACES is OBJECT_PLACES
    assert relrl.sim.sis.POSES is SIS_POSES
    assert relrl.episodes.script.PLACES is PLACES
    assert relrl.episodes.script.OBJECT_PLACES is OBJECT_PLACES
    assert relrl.episodes.world.GAZE_POSE is GAZE_POSE
    assert set(GAZE_POSE) == set(PLACES) and set(GAZE_POSE.values()) == set(POSES)


@pytest.mark.parametrize("module", ["head", "perception", "perception.vocabulary",
                                    "head.errors", "perception.errors"])
@pytest.mark.slow
def test_lower_layers_stand_alone(module: str) -> None:
    code = (f"import sys, {module}; print(sorted({{m.split('.')[0] for m in sys.modules}} & "
            "{'relrl', 'gymnasium', 'cv2', 'pyswip', 'numpy'}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout
    assert out.strip() == "[]", f"import {module} imported {out.strip()}"


def test_import_relrl_imports_no_gymnasium() -> None:
    code = "import sys, relrl, relrl.errors; print('gymnasium' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout
    assert out.strip() == "False"


def test_the_two_worlds_perceive_the_caregiver_differently() -> None:
    assert WORLDS["sis"].allows(("pose", "face", "left"))
    assert not WORLDS["sis"].allows(("pose", "face", "left_2"))
    assert WORLDS["episodes"].allows(("pose", "face", "left_2"))
    assert not WORLDS["episodes"].allows(("pose", "face", "left"))
    assert WORLDS["episodes"].allows(("hear", "apple")) and not WORLDS["sis"].allows(
        ("hear", "apple"))
    assert WORLDS["episodes"].allows(("colour", "object", "blue"))
    assert not WORLDS["fruits"].allows(("colour", "object", "blue"))
    assert not WORLDS["sis"].allows("see") and not WORLDS["sis"].allows(("se", "face"))


def test_terms_expand_the_choices() -> None:
    terms = WORLDS["sis"].terms()
    assert ("pose", "face", "frontal") in terms and ("at", "toy", "left") in terms
    assert ("colour", "toy", ANY) in terms and ("at", "toy", "centre") not in terms
    assert "pose(face, frontal|left|left_down|down|right_down|right)" in WORLDS["sis"].lines()


def test_unknown_world_suggests_one() -> None:
    with pytest.raises(ValueError, match="did you mean 'sis'"):
        world("siss")


def test_growing_worlds_build_their_vocabulary() -> None:
    places = ("centre",) + tuple(f"p{i}" for i in range(8))
    vocab = percepts.sis_vocabulary(places, name="grown")
    assert vocab.allows(("pose", "face", "p7")) and vocab.allows(("at", "toy", "p0"))
    assert not vocab.allows(("at", "toy", "centre"))


@pytest.mark.slow
def test_the_simulator_stays_in_the_sis_vocabulary_and_meets_every_pattern() -> None:
    from relrl.sim import SharedAttentionEnv

    env = SharedAttentionEnv(max_steps=None)
    env.reset(seed=4)
    rng = np.random.default_rng(1)
    met = set()
    for _ in range(4000):
        _, _, _, _, info = env.step(int(rng.integers(len(PLACES))))
        for p in info["percepts"]:
            assert WORLDS["sis"].allows(p), p
            met.update(i for i, pattern in enumerate(WORLDS["sis"].patterns)
                       if percepts.Vocabulary("", "", (pattern,)).allows(p))
    assert met == set(range(len(WORLDS["sis"].patterns)))


@pytest.mark.parametrize("perception", ["symbolic", "render"])
@pytest.mark.slow
def test_the_episode_world_stays_in_the_episodes_vocabulary(perception: str) -> None:
    from relrl.episodes import EpisodeWorld, parse_episode

    text = (f'[episode]\ndomain = "{ROOT / "examples/domains/fruits.pl"}"\nseed = 2\n'
            f'[world]\nperception = "{perception}"\n[caregiver]\ncontact_hold = 1\n'
            '[[phase]]\nname = "fruits"\nsteps = 400\n')
    env = EpisodeWorld(parse_episode(text, "v.toml"))
    env.reset(seed=0, options={"focus": "centre"})
    rng = np.random.default_rng(2)
    steps = 400 if perception == "symbolic" else 40
    poses = set()
    for _ in range(steps):
        action = ("look", PLACES[int(rng.integers(len(PLACES)))]) if rng.random() < 0.8 \
            else "name_object"
        _, _, _, _, info = env.step(action)
        for p in info["percepts"]:
            assert WORLDS["episodes"].allows(p), p
            if perception == "symbolic":
                assert WORLDS["fruits"].allows(p), p
            if p[0] == "pose":
                poses.add(p[2])
    assert poses and poses <= set(POSES)
