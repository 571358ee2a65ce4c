"""The evaluation protocol as a function: scripted policies, splits, seeds, large worlds."""

from __future__ import annotations

import pytest

from relrl.sim import World, evaluate, evaluation_seeds
from relrl.sim.errors import SimError
from relrl.sim.policies import GazeFollower, RandomPolicy


def follower():
    g = GazeFollower()
    return lambda obs, info: g(info["percepts"])


def test_a_gaze_follower_scores_one_in_every_run() -> None:
    result = evaluate(follower(), runs=4, steps=200)
    assert result.cgi == [1.0] * 4 and result.cgi_literal == [1.0] * 4
    assert result.cgi_mean == 1.0 and result.cgi_std == 0.0
    assert all(r["eye_contacts"] > 20 for r in result.runs)


def test_a_robot_that_never_leaves_the_face_scores_zero_not_nan() -> None:
    result = evaluate(lambda obs, info: 0, runs=2, steps=100)
    assert result.cgi == [0.0, 0.0] and result.runs[0]["shifts"] == 0


def test_the_runs_split_into_parts_that_join_to_the_whole() -> None:
    rp = RandomPolicy(seed=0)

    def policy(obs, info):
        return rp(info["percepts"])

    whole = evaluate(policy, runs=4, steps=150, seed=7, on_run=lambda k, s: rp.__init__(s))
    parts = [evaluate(policy, runs=4, steps=150, seed=7, which=w,
                      on_run=lambda k, s: rp.__init__(s)) for w in [(0, 1), (1, 4)]]
    assert [r for p in parts for r in p.runs] == whole.runs
    assert [r["seed"] for r in whole.runs] == evaluation_seeds(7, 4)
    assert evaluate(policy, runs=4, steps=150, seed=8,
                    on_run=lambda k, s: rp.__init__(s)).runs != whole.runs


def test_the_runs_together_cover_every_place_of_a_large_world() -> None:
    world = World(places=33)
    targets: set[str] = set()
    g = GazeFollower()

    def policy(obs, info):
        rec = info["record"]
        if rec.target:
            targets.add(rec.target)
        return g(info["percepts"])

    result = evaluate(policy, world=world, runs=10, steps=200)
    assert result.cgi_mean == 1.0
    assert targets == set(world.layout.toy_places)


def test_held_out_places_as_the_sequence() -> None:
    seen: set[str] = set()
    g = GazeFollower()

    def policy(obs, info):
        if info["record"].target:
            seen.add(info["record"].target)
        return g(info["percepts"])

    evaluate(policy, runs=3, steps=200, sequence=["left_down", "right"])
    assert seen == {"left_down", "right"}


@pytest.mark.parametrize("kwargs", [{"runs": 0}, {"steps": 0}])
def test_bad_sizes_are_user_errors(kwargs) -> None:
    with pytest.raises(SimError, match="whole numbers"):
        evaluate(follower(), **kwargs)
