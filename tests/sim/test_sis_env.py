"""The SIS as a Gymnasium environment and as relrl's Environment."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import relrl
from relrl.errors import UserError
from relrl.interfaces import Environment
from relrl.sim import SharedAttentionEnv
from relrl.sim.errors import InvalidResponse, SimError
from relrl.sim.places import ANGLE_BETWEEN, PLACES, place_index
from relrl.sim.render import IMAGE_SHAPE
from relrl.sim.sis import ENV_ID, POSES

SIS_DOMAIN = Path(__file__).resolve().parents[2] / "examples" / "domains" / "sis.pl"


def run(env: SharedAttentionEnv, actions, seed: int):
    obs, info = env.reset(seed=seed)
    out = [(obs.tolist(), info["percepts"])]
    for a in actions:
        obs, reward, term, trunc, info = env.step(a)
        out.append((obs.tolist(), reward, term, trunc, info["percepts"]))
    return out, list(env.trace)


def to_contact(env: SharedAttentionEnv) -> dict:
    """Reset looking at the face and hold it: the info of the time unit of eye contact."""
    env.reset(seed=0, options={"focus": "centre"})
    env.step(0)
    _, _, _, _, info = env.step(0)
    assert info["record"].contact
    return info


@pytest.mark.parametrize("mode", [None, "ansi", "rgb_array"])
def test_passes_gymnasium_env_checker_without_warnings(mode: str | None) -> None:
    env = gym.make(ENV_ID, render_mode=mode).unwrapped   # check_env wants the raw env
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env)


def test_registered_when_the_simulator_is_imported() -> None:
    assert relrl.__version__ and ENV_ID == "relrl/SharedAttention-v0"
    env = gym.make(ENV_ID, caregiver="unreliable", max_steps=7)
    assert isinstance(env.unwrapped, SharedAttentionEnv)
    assert env.unwrapped.caregiver.params.reliability == 0.5
    env.reset(seed=1)
    truncs = [env.step(env.action_space.sample())[3] for _ in range(7)]
    assert truncs == [False] * 6 + [True]
    env.close()


def test_is_a_relrl_environment() -> None:
    assert isinstance(SharedAttentionEnv(), Environment)


def test_same_seed_same_trajectory_different_seed_differs() -> None:
    actions = np.random.default_rng(7).integers(0, 6, size=3000).tolist()
    a = run(SharedAttentionEnv(max_steps=None), actions, seed=11)
    b = run(SharedAttentionEnv(max_steps=None), actions, seed=11)
    c = run(SharedAttentionEnv(max_steps=None), actions, seed=12)
    assert a == b
    assert a[1] != c[1]
    assert any(rec.toys for rec in a[1])   # the run went through toy trials


def test_percept_vocabulary_matches_the_sis_domain() -> None:
    text = SIS_DOMAIN.read_text()
    assert set(re.findall(r"percept\(pose\(face, (\w+)\)\)", text)) == set(POSES)
    assert set(re.findall(r"response\(look\((\w+)\)\)", text)) == set(PLACES)
    assert set(re.findall(r"fact\(head_at\((\w+)\)\)", text)) == set(PLACES)
    assert set(re.findall(r"^stimulus\((\w+)\)", text, re.MULTILINE)) == {
        "face", "toy", "attention", "environment"}


def test_percepts_show_only_the_focus() -> None:
    env = SharedAttentionEnv()
    info = to_contact(env)
    assert ("hear", "attention") in info["percepts"]          # eye contact rewarded
    _, _, _, _, info = env.step(("look", "centre"))           # the caregiver has turned
    rec = info["record"]
    assert info["percepts"] == [("see", "face"), ("pose", "face", rec.gaze), ("at", "centre")]
    empty = next(p for p in PLACES[1:] if p not in dict(rec.toys))
    _, reward, _, _, info = env.step(f"look({empty})")
    assert info["percepts"] == [("see", "environment"), ("at", empty)] and reward == -1.0
    distractor, colour = rec.toys[1]
    _, reward, _, _, info = env.step(("look", distractor))
    assert info["percepts"] == [("see", "toy"), ("at", "toy", distractor),
                                ("colour", "toy", colour), ("at", distractor)]
    target, colour = rec.toys[0]
    _, reward, _, _, info = env.step(("look", target))
    assert info["percepts"] == [("see", "toy"), ("at", "toy", target),
                                ("colour", "toy", colour), ("at", target), ("hear", "attention")]
    assert reward == 10.0


def test_observation_encodes_the_percepts() -> None:
    env = SharedAttentionEnv(max_steps=None)
    obs, _ = env.reset(seed=3)
    rng = np.random.default_rng(0)
    colours = env.caregiver.params.toy_colours
    for _ in range(3000):
        obs, _, _, _, info = env.step(int(rng.integers(6)))
        per = info["percepts"]
        assert env.observation_space.contains(obs)
        assert obs[0] == place_index(env.focus) and ("at", env.focus) in per
        assert obs[4] == (("hear", "attention") in per)
        if obs[1] == 1:
            assert per[1] == ("pose", "face", POSES[obs[2] - 1])
        else:
            assert obs[2] == 0 and per[0] == (("see", "toy") if obs[1] == 2
                                              else ("see", "environment"))
        if obs[3]:
            assert ("colour", "toy", colours[obs[3] - 1]) in per


def test_observations_are_fresh_arrays() -> None:
    env = SharedAttentionEnv()
    a, _ = env.reset(seed=0, options={"focus": "centre"})
    b = env.step(0)[0]
    a[0] = 5
    assert b[0] == 0 and env.step(0)[0][0] == 0


def test_step_takes_index_term_text_and_numpy_integer() -> None:
    env = SharedAttentionEnv()
    env.reset(seed=0)
    for action, place in [(3, "down"), (("look", "left"), "left"), ("look(right)", "right"),
                          (np.int64(0), "centre")]:
        env.step(action)
        assert env.focus == place


@pytest.mark.parametrize("bad", [6, -1, ("look", "up"), "look(lefft)", [1], None])
def test_bad_response_is_a_user_error(bad) -> None:
    env = SharedAttentionEnv()
    env.reset(seed=0)
    with pytest.raises(InvalidResponse, match="not a response of the SIS") as err:
        env.step(bad)
    assert isinstance(err.value, UserError)


def test_did_you_mean_for_a_misspelt_response() -> None:
    env = SharedAttentionEnv()
    env.reset(seed=0)
    with pytest.raises(InvalidResponse, match=r"did you mean 'look\(left\)'"):
        env.step("look(lefft)")


def test_bad_construction_and_order() -> None:
    with pytest.raises(SimError, match="render_mode='human'"):
        SharedAttentionEnv(render_mode="human")
    with pytest.raises(SimError, match="max_steps=0"):
        SharedAttentionEnv(max_steps=0)
    with pytest.raises(SimError, match="did you mean 'centre'"):
        SharedAttentionEnv(initial_focus="center")
    with pytest.raises(SimError, match="reset"):
        SharedAttentionEnv().step(0)


def test_rewards_are_configurable() -> None:
    env = SharedAttentionEnv(reward_attention=1.0, reward_other=0.0)
    env.reset(seed=0, options={"focus": "centre"})
    assert [env.step(0)[1] for _ in range(2)] == [0.0, 1.0]


def test_toy_angles_are_the_head_turns_to_each_toy() -> None:
    env = SharedAttentionEnv()
    to_contact(env)
    _, _, _, _, info = env.step(0)
    rec = info["record"]
    c = place_index("centre")
    assert info["toy_angles"] == tuple((p, ANGLE_BETWEEN[c][place_index(p)]) for p, _ in rec.toys)
    target = rec.toys[0][0]
    _, _, _, _, info = env.step(("look", target))
    assert dict(info["toy_angles"])[target] == 0.0
    assert all(0 < a <= 180 for p, a in info["toy_angles"] if p != target)


def test_trace_has_one_record_per_time_unit_and_can_be_turned_off() -> None:
    env = SharedAttentionEnv()
    env.reset(seed=0)
    first = env.trace
    for _ in range(5):
        env.step(0)
    assert [r.t for r in env.trace] == list(range(6)) and env.trace[-1] == env.record
    env.reset(seed=0)
    assert first is not env.trace and len(first) == 6     # a kept trace stays intact
    quiet = SharedAttentionEnv(record_trace=False)
    quiet.reset(seed=0)
    assert quiet.step(0)[4]["record"].t == 1 and quiet.trace == []


def test_renders_text_and_a_top_view() -> None:
    env = SharedAttentionEnv(render_mode="ansi")
    to_contact(env)
    text = env.render()
    assert "EYE CONTACT" in text and "ATTENTION" in text and "robot looks at centre" in text
    env.step(0)
    assert "caregiver looks at " + env.record.gaze in env.render()
    rgb = SharedAttentionEnv(render_mode="rgb_array")
    rgb.reset(seed=0, options={"focus": "centre"})
    before = rgb.render()
    for _ in range(3):
        rgb.step(0)
    after = rgb.render()
    assert before.shape == after.shape == IMAGE_SHAPE and after.dtype == np.uint8
    red = (after[..., 0] > 200) & (after[..., 1] < 60)
    assert red.sum() > 50 and not ((before[..., 0] > 200) & (before[..., 1] < 60)).any()


def test_close_twice() -> None:
    env = SharedAttentionEnv()
    env.close()
    env.close()
