"""The outside benchmark: metrics in info, the successor id, the relational wrapper, the
tabular example."""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from relrl.kb import KnowledgeBase
from relrl.sim import ENV_ID, ENV_ID_V1, GazeMetrics, World
from relrl.sim.policies import GazeFollower, RandomPolicy
from relrl.sim.wrappers import RelationalObservation, relational_facts

ROOT = Path(__file__).resolve().parents[2]


def test_info_holds_the_episodes_metrics_at_truncation_only() -> None:
    env = gym.make(ENV_ID, max_steps=300)
    _, info = env.reset(seed=4)
    follower = GazeFollower()
    for t in range(300):
        _, _, _, truncated, info = env.step(follower(info["percepts"]))
        assert ("cgi" in info) == truncated == (t == 299)
    m = GazeMetrics().extend(env.unwrapped.trace)
    assert info["cgi"] == m.cgi().value == 1.0
    assert info["cgi_literal"] == m.cgi_literal().value
    assert info["eye_contacts"] == m.eye_contacts().established > 30
    assert info["opportunities"] == m.eye_contacts().opportunities


@pytest.mark.parametrize("world", [None, {"places": 9, "kinds": 3},
                                   {"places": 17, "colours": 3, "kinds": 2, "scene": True}])
def test_v1_passes_the_env_checker(world) -> None:
    env = gym.make(ENV_ID_V1, **({"world": world} if world else {})).unwrapped
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env)
    assert len(env.observation_fields) == len(env.observation_space.nvec)


def test_v0_observation_is_unchanged_by_v1() -> None:
    v0, v1 = gym.make(ENV_ID).unwrapped, gym.make(ENV_ID_V1).unwrapped
    assert v0.observation_space.nvec.tolist() == [6, 3, 7, 3, 2]
    assert v1.observation_space.nvec.tolist() == [6, 3, 7, 3, 1, 2]


def test_v1_observation_encodes_the_scene() -> None:
    world = World(places=9, colours=3, kinds=2, scene=True, field=50)
    env = world.env(observation=1, max_steps=None)
    rp = RandomPolicy(2, env.places)
    _, info = env.reset(seed=2)
    names = [f for f, _ in env.observation_fields]
    for _ in range(2000):
        obs, _, _, _, info = env.step(rp(info["percepts"]))
        assert env.observation_space.contains(obs)
        in_view = {p[1]: p[2:] for p in info["percepts"] if p[0] == "in_view"}
        for place in env.places[1:]:
            cell = obs[names.index(f"scene_{place}")]
            if place in in_view:
                colour, kind = in_view[place]
                assert cell == 1 + world.colour_names.index(colour) * 2 + \
                    world.kind_names.index(kind)
            else:
                assert cell == 0
        kinds = [p[2] for p in info["percepts"] if p[:2] == ("kind", "toy")]
        assert obs[names.index("kind")] == (1 + world.kind_names.index(kinds[0]) if kinds else 0)


@pytest.mark.parametrize("world", [World(places=9, kinds=2),
                                   World(places=9, colours=3, kinds=2, scene=True)])
def test_the_wrapper_gives_what_the_domains_relations_give(world: World, tmp_path: Path) -> None:
    """The relational view computed in Python equals the generated domain's relation/1."""
    kb = KnowledgeBase(world.write_domain(tmp_path))
    try:
        env = RelationalObservation(world.env(observation=1, max_steps=None))
        follower, rp = GazeFollower(), RandomPolicy(3, env.unwrapped.places)
        obs, info = env.reset(seed=3)
        for t in range(400):
            kb.insert(info["percepts"])
            solutions, _ = kb.query("findall(T, (relation(T), call(T)), L0), sort(L0, L)")
            printed = next(p for name, _, p in solutions[0] if name == "L")
            prolog = sorted(_split(printed))
            assert list(obs) == prolog == sorted(info["relational"])
            policy = follower if t % 3 else rp
            obs, _, _, _, info = env.step(policy(info["percepts"]))
    finally:
        kb.close()


def _split(printed: str) -> list[str]:
    """Split a printed Prolog list of ground terms into its elements (no spaces)."""
    text, out, depth, start = printed.replace(" ", "")[1:-1], [], 0, 0
    for i, ch in enumerate(text):
        depth += ch == "("
        depth -= ch == ")"
        if ch == "," and depth == 0:
            out.append(text[start:i])
            start = i + 1
    if text:
        out.append(text[start:])
    return out


def test_relational_facts_by_hand() -> None:
    assert relational_facts([("see", "face"), ("pose", "face", "frontal"), ("at", "centre"),
                             ("hear", "attention")]) == (
        "gaze(face,centre)", "head_at(centre)", "heard(attention)", "sees(face)")
    assert relational_facts([("see", "toy"), ("at", "toy", "left"), ("colour", "toy", "red"),
                             ("in_view", "left", "red", "none"), ("at", "left")],
                            scene=True) == (
        "colour(toy(left),red)", "head_at(left)", "sees(toy)", "toy_at(toy(left),left)")


def test_the_tabular_example_learns_and_reports_the_protocols_cgi() -> None:
    spec = importlib.util.spec_from_file_location("gym_tabular_q",
                                                  ROOT / "examples" / "gym_tabular_q.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    result = module.main(["--steps", "20000", "--seed", "1"])
    assert result["cgi"] > 0.8 and result["rows"] > 5
    assert np.isfinite(result["cgi_literal"])
