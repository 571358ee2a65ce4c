"""Reward accounting: no farming, and one reward definition for the env, the learners and the
experiments."""

from __future__ import annotations

import pytest

from relrl.experiments.sis import DEFAULT_DOMAIN, SISConfig
from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.learners.base import COMMON_DEFAULTS
from relrl.loop import Agent, Interaction
from relrl.sim import PAPER_REWARD, SharedAttentionEnv, World
from relrl.sim.policies import GazeFollower


class Farmer:
    """The loophole an outside tabular agent found: look(centre), look(down), again and again
    (it never holds eye contact, so toys never come)."""

    def __init__(self, pattern: tuple[str, ...] = ("centre", "down")) -> None:
        self.pattern, self.t = pattern, 0

    def __call__(self, percepts) -> tuple[str, str]:
        self.t += 1
        return ("look", self.pattern[self.t % len(self.pattern)])


def mean_reward(env: SharedAttentionEnv, policy, steps: int = 3000, seed: int = 0) -> float:
    _, info = env.reset(seed=seed)
    total = 0.0
    for _ in range(steps):
        _, reward, _, _, info = env.step(policy(info["percepts"]))
        total += reward
    return total / steps


@pytest.mark.parametrize("during_gaze", [False, True])
@pytest.mark.parametrize("pattern", [("centre", "down"), ("centre", "centre", "down"),
                                     ("centre", "left", "down")])
@pytest.mark.slow
def test_a_farming_policy_earns_less_than_gaze_following(during_gaze: bool,
                                                         pattern: tuple[str, ...]) -> None:
    params = {"attention_during_gaze": during_gaze}
    farm = mean_reward(SharedAttentionEnv(caregiver_params=params, max_steps=None),
                       Farmer(pattern))
    follow = mean_reward(SharedAttentionEnv(caregiver_params=params, max_steps=None),
                         GazeFollower())
    assert follow > 2.0 and farm < follow / 10
    # at most one attention per opportunity of contact_timeout (10) time units
    gain = PAPER_REWARD.attention - PAPER_REWARD.other
    assert farm <= PAPER_REWARD.other + gain * (3000 // 10 + 1) / 3000 + 1e-9


@pytest.mark.slow
def test_farming_loses_in_large_worlds_and_with_an_unreliable_caregiver() -> None:
    for world, params in [(World(places=17), {}), (World(), {"reliability": 0.5})]:
        def env(world: World = world, params: dict = params) -> SharedAttentionEnv:
            return SharedAttentionEnv(world=world, caregiver_params=params, max_steps=None)

        farm = mean_reward(env(), Farmer())
        follow = mean_reward(env(), GazeFollower())
        assert farm < follow


def test_the_env_and_the_experiments_share_one_task_and_reward() -> None:
    env = SharedAttentionEnv()
    config = SISConfig()
    assert config.caregiver_params == {}
    assert config.to_dict()["caregiver_resolved"] == env.caregiver.params.to_dict()
    assert (env.reward_attention, env.reward_other) == (PAPER_REWARD.attention,
                                                        PAPER_REWARD.other)
    assert (COMMON_DEFAULTS["reward_positive"], COMMON_DEFAULTS["reward_negative"]) == (
        PAPER_REWARD.attention, PAPER_REWARD.other)


@pytest.mark.parametrize("learner", ["qlearning", "etg"])
@pytest.mark.slow
def test_the_learners_reward_is_the_envs_time_unit_by_time_unit(learner: str) -> None:
    kb = KnowledgeBase(DEFAULT_DOMAIN)
    try:
        agent = Agent(kb, make_learner(learner), seed=3)
        env_rewards: list[float] = []
        seen: list[float] = []
        run = Interaction(SharedAttentionEnv(max_steps=None), agent,
                          on_step=lambda r: (env_rewards.append(r.env_reward),
                                             seen.append(r.out.reward)))
        run.reset(seed=3)
        run.run(1500)
        # the engine's reward at step t is for the response of step t-1
        assert seen[1:] == env_rewards[:-1]
        assert PAPER_REWARD.attention in env_rewards and PAPER_REWARD.other in env_rewards
    finally:
        kb.close()
