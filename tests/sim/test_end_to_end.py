"""Scripted robots on the simulator: the metrics reach the values they must."""

from __future__ import annotations

import math

import pytest

from relrl.sim import GazeMetrics, SharedAttentionEnv
from relrl.sim.policies import GazeFollower, RandomPolicy, bench_step_rate, rollout


def metrics(trace) -> GazeMetrics:
    return GazeMetrics().extend(trace)


def test_gaze_follower_reaches_cgi_one_and_eye_contact_in_every_opportunity() -> None:
    env = SharedAttentionEnv(max_steps=None)
    trace = rollout(env, GazeFollower(), 3000, seed=1)
    m = metrics(trace)
    c = m.cgi()
    assert c.value == 1.0 and c.shifts > 300
    e = m.eye_contacts(first=125)
    assert e.opportunities == 125 and e.established == 125
    trials = max(r.trial for r in trace) + 1
    # every trial ends with attention for following the gaze; every contact with attention
    assert sum(r.attention for r in trace) == trials + sum(r.contact for r in trace)
    assert m.mutual_gaze_events == sum(r.contact for r in trace)


def test_gaze_follower_meets_the_evaluation_sequence() -> None:
    env = SharedAttentionEnv(caregiver_params={"target_sequence": ("left", "down")},
                             max_steps=None)
    trace = rollout(env, GazeFollower(), 200, seed=2)
    targets = [r.target for r in trace if r.target and r.phase == "attend"]
    followed = [r.focus for r in trace if r.attention and r.target]
    assert followed[:6] == ["left", "down"] * 3 and set(targets) == {"left", "down"}


@pytest.mark.slow
def test_unreliable_caregiver_lowers_the_followers_reward_not_its_cgi() -> None:
    follow = rollout(SharedAttentionEnv(max_steps=None), GazeFollower(), 3000, seed=3)
    shaky = rollout(SharedAttentionEnv("unreliable", max_steps=None), GazeFollower(), 3000,
                    seed=3)
    assert metrics(shaky).cgi().value == 1.0   # it still looks where the caregiver looks
    rate = [sum(r.attention for r in tr) / len(tr) for tr in (follow, shaky)]
    assert rate[1] < 0.8 * rate[0]


@pytest.mark.slow
def test_random_robot_cgi_is_near_one_fifth() -> None:
    env = SharedAttentionEnv(max_steps=None, record_trace=True)
    trace = rollout(env, RandomPolicy(seed=4), 150_000, seed=4)
    m = metrics(trace)
    c = m.cgi()
    assert c.shifts > 200
    assert abs(c.value - 0.2) < 0.07, c  # 3 standard errors
    e = m.eye_contacts(first=None)
    assert e.established == sum(r.contact for r in trace)     # metric agrees with caregiver
    assert 0 < e.established < e.opportunities / 5            # a random robot rarely holds it


def test_step_rate_benchmark_reports_a_rate() -> None:
    result = bench_step_rate(steps=2000)
    assert result["steps"] == 2000 and result["steps_per_second"] > 0
    assert math.isclose(result["steps"] / result["seconds"], result["steps_per_second"])


@pytest.mark.parametrize("steps", [1, 500])
def test_rollout_returns_reset_record_and_every_step(steps: int) -> None:
    trace = rollout(SharedAttentionEnv(max_steps=None), GazeFollower(), steps, seed=0)
    assert len(trace) == steps + 1 and trace[0].t == 0
