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
from relrl.sim import ENV_ID, ENV_ID_V1, GazeMetrics, SharedAttentionEnv, World
from relrl.sim.policies import GazeFollower, RandomPolicy
from relrl.sim.wrappers import RelationalObservation, RelationalView

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
    env = SharedAttentionEnv(world=world, observation=1, max_steps=None)
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
@pytest.mark.slow
def test_the_wrapper_gives_what_the_domains_relations_give(world: World, tmp_path: Path) -> None:
    """The wrapper's view is the generated domain's relation/1, asked of a knowledge base of
    its own, time unit by time unit, and every fact it gives is ground text of a template."""
    kb = KnowledgeBase(world.write_domain(tmp_path))
    env = RelationalObservation(SharedAttentionEnv(world=world, observation=1, max_steps=None))
    try:
        follower, rp = GazeFollower(), RandomPolicy(3, env.unwrapped.places)
        obs, info = env.reset(seed=3)
        seen = set()
        for t in range(400):
            kb.insert(info["percepts"])
            solutions, _ = kb.query("findall(T, (relation(T), call(T)), L0), sort(L0, L)")
            printed = next(p for name, _, p in solutions[0] if name == "L")
            assert list(obs) == sorted(_split(printed)) == list(info["relational"])
            seen.update(f.split("(")[0] for f in obs)
            policy = follower if t % 3 else rp
            obs, _, _, _, info = env.step(policy(info["percepts"]))
        assert {"sees", "gaze", "head_at", "toy_at", "colour", "kind"} <= seen
    finally:
        env.close()
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


def test_the_relational_view_by_hand() -> None:
    with RelationalView(World()) as view:
        assert view([("see", "face"), ("pose", "face", "frontal"), ("at", "centre"),
                     ("hear", "attention")]) == (
            "gaze(face,centre)", "head_at(centre)", "heard(attention)", "sees(face)")
        assert view([("see", "environment"), ("at", "down")]) == (
            "head_at(down)", "sees(environment)")
    with RelationalView(World(scene=True)) as view:
        assert view([("see", "toy"), ("at", "toy", "left"), ("colour", "toy", "red"),
                     ("in_view", "left", "red", "none"), ("at", "left")]) == (
            "colour(toy(left),red)", "head_at(left)", "sees(toy)", "toy_at(toy(left),left)")


@pytest.mark.slow
def test_the_tabular_example_learns_and_reports_the_protocols_cgi() -> None:
    spec = importlib.util.spec_from_file_location("gym_tabular_q",
                                                  ROOT / "examples" / "gym_tabular_q.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    result = module.main(["--steps", "20000", "--seed", "1"])
    assert result["cgi"] > 0.8 and result["rows"] > 5
    assert np.isfinite(result["cgi_literal"])


#: what a Discrete action space contains besides a Python int: numpy integers and 0-d
#: integer arrays (Stable-Baselines3's ``model.predict(obs)`` returns ``np.array(a)``), bool.
CONTAINED = [np.array(0), np.array(3, dtype=np.int32), np.array(5, dtype=np.int8),
             np.int64(2), np.int16(4), np.uint8(1), True, 1]


@pytest.mark.parametrize("env_id", [ENV_ID, ENV_ID_V1])
def test_step_takes_everything_the_action_space_contains(env_id: str) -> None:
    """Through ``gym.make`` (its checker and wrappers) as a training loop calls it."""
    env = gym.make(env_id)
    env.reset(seed=0)
    places = env.unwrapped.places
    for action in CONTAINED:
        assert env.action_space.contains(action), action
        env.step(action)
        assert env.unwrapped.focus == places[int(action)], action


def test_a_stable_baselines3_style_loop_runs() -> None:
    """The loop of SB3's documentation: ``action, _ = model.predict(obs)`` gives a 0-d
    integer array for one observation, stepped as it is (it used to raise)."""
    def predict(obs: np.ndarray) -> tuple[np.ndarray, None]:  # SB3's predict, its shapes
        batch = np.asarray([int(obs[0]) % 6])                 # one action per observation
        return batch.squeeze(axis=0), None

    env = gym.make(ENV_ID, max_steps=50)
    obs, _ = env.reset(seed=1)
    for _ in range(50):
        action, _states = predict(obs)
        assert isinstance(action, np.ndarray) and action.shape == ()
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            obs, _ = env.reset()
    check_env(env.unwrapped, skip_render_check=True)


@pytest.mark.parametrize("bad", [1.0, np.array([0]), np.array(0.0), np.uint64(1), 6,
                                 np.array(6), None])
def test_what_the_action_space_does_not_contain_is_refused(bad) -> None:
    from relrl.sim.errors import InvalidResponse

    env = gym.make(ENV_ID)
    env.reset(seed=0)
    assert not env.action_space.contains(bad)
    with pytest.raises(InvalidResponse, match="not a response of the SIS"):
        env.step(bad)


@pytest.mark.parametrize("options, message", [
    (5, r"options=5: use a dict such as \{'focus': 'centre'\}"),
    ("focus", r"options='focus': use a dict"),
    ({"fokus": "left"}, r"unknown reset option 'fokus'; did you mean 'focus'\?"),
])
def test_reset_options_that_are_not_a_dict_of_known_options(options, message: str) -> None:
    """``reset(options=5)`` used to end in an AttributeError; a misspelt option was ignored."""
    from relrl.sim.errors import SimError

    env = gym.make(ENV_ID)
    with pytest.raises(SimError, match=message):
        env.reset(seed=0, options=options)
    env.reset(seed=0, options={"focus": "left"})
    assert env.unwrapped.focus == "left"
    env.reset(seed=0, options=None)
    env.reset(seed=0, options={})
