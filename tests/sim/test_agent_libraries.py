"""An outside agent through the standard Gymnasium loop, with every episode's CGI (from
``info`` at the episode's end) in TensorBoard: the small tabular agent of
``examples/gym_tabular_q.py`` here; Stable-Baselines3's PPO and DQN in
``examples/sb3_shared_attention.py`` (``make sb3``), through the same wrapper."""

from __future__ import annotations

import importlib.util
import math
import statistics
from pathlib import Path

import gymnasium as gym
import pytest
from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

import relrl.sim  # noqa: F401 - registers the environments
from relrl.sim.wrappers import EpisodeScalars
from tests.conftest import ROOT

pytestmark = pytest.mark.slow  # every test here takes a second or more


def _example(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_tabular_agent_trains_with_each_episodes_cgi_in_tensorboard(tmp_path: Path) -> None:
    tabular = _example("gym_tabular_q")
    env = EpisodeScalars(gym.make("relrl/SharedAttention-v1", max_steps=500), tmp_path)
    table = tabular.train(env, 15_000, seed=1)          # reset, step, ..., reset at truncation
    env.close()
    episodes = env.episodes
    assert len(episodes) == 30 and all(e["length"] == 500 for e in episodes)
    cgi = [e["cgi"] for e in episodes]
    assert statistics.mean(cgi[-5:]) > statistics.mean(cgi[:5]) + 0.2, cgi   # it learns
    ea = EventAccumulator(str(tmp_path))
    ea.Reload()
    shown = ea.Scalars("episode/cgi")
    assert [(e.step, round(e.value, 6)) for e in shown] == [
        (500 * (k + 1), round(c, 6)) for k, c in enumerate(cgi) if math.isfinite(c)]
    assert [e.value for e in ea.Scalars("episode/return")] == [e["return"] for e in episodes]
    assert {"episode/eye_contacts", "episode/opportunities", "episode/shifts"} <= \
        set(ea.Tags()["scalars"])
    assert len(table) > 5
