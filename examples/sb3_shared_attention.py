"""Train Stable-Baselines3's PPO or DQN on relrl's Gymnasium task, follow the gaze-following
CGI of every episode from ``info`` in TensorBoard, and evaluate the trained policy by the
paper's protocol -- the way a lab would try its usual agent library on relrl.

    make sb3                    # torch's CPU build and Stable-Baselines3 ('relrl[sb3]')
    .venv/bin/python examples/sb3_shared_attention.py --algo ppo --steps 100000
    .venv/bin/python examples/sb3_shared_attention.py --algo dqn --steps 100000
    tensorboard --logdir runs/sb3                      # episode/cgi, episode/return, ...
    .venv/bin/python examples/sb3_shared_attention.py --algo ppo --steps 20000 --check

Nothing here is special to relrl but two lines: the environment's name and
:class:`relrl.sim.wrappers.EpisodeScalars`, which writes each episode's return and the gaze
metrics ``info`` holds at its end (``cgi``, ``eye_contacts``, ...) as TensorBoard scalars.
Stable-Baselines3's own numbers (losses, rollout means) go to ``progress.csv`` beside them
(pandas reads it; TensorBoard too when its ``tensorboard`` package is installed). The
actions ``model.predict`` returns are stepped as they are. ``--check`` exits 1 unless the
trained policy's CGI beats the untrained one's by 0.1 (what ``make sb3`` runs).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import gymnasium as gym

from relrl.sim import evaluate  # importing relrl.sim registers relrl/SharedAttention-v0, -v1
from relrl.sim.wrappers import EpisodeScalars

ALGOS = ("ppo", "dqn")


def make_model(algo: str, env: gym.Env, seed: int):
    """A Stable-Baselines3 model with settings that suit a short, discrete task (an episode
    is 500 time units; the reward is +10 for attention, -1 otherwise)."""
    from stable_baselines3 import DQN, PPO

    if algo == "ppo":
        return PPO("MlpPolicy", env, n_steps=1024, batch_size=256, gamma=0.9, ent_coef=0.01,
                   learning_rate=1e-3, seed=seed, device="cpu", verbose=0)
    return DQN("MlpPolicy", env, learning_rate=1e-3, buffer_size=50_000, learning_starts=1000,
               train_freq=4, target_update_interval=1000, exploration_fraction=0.3,
               exploration_final_eps=0.05, gamma=0.9, seed=seed, device="cpu", verbose=0)


def cgi_of(model, seed: int, runs: int = 10) -> float:
    """The CGI of the model's greedy policy by the paper's protocol (runs x 500 time units,
    no learning), as relrl's experiments evaluate their learners."""
    def policy(obs, info):
        action, _ = model.predict(obs, deterministic=True)   # a 0-d array: stepped as it is
        return action

    return evaluate(policy, runs=runs, steps=500, seed=seed, observation=1).cgi_mean


def main(argv: list[str] | None = None) -> dict:
    """Train, evaluate, print and return the CGI before and after."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--algo", choices=ALGOS, default="ppo")
    parser.add_argument("--steps", type=int, default=100_000, help="learning time units")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--logdir", default="runs/sb3", help="TensorBoard's folder")
    parser.add_argument("--check", action="store_true",
                        help="exit 1 unless the CGI rose by 0.1 or more")
    args = parser.parse_args(argv)
    from stable_baselines3.common.logger import configure

    folder = Path(args.logdir) / f"{args.algo}-seed{args.seed}"
    env = EpisodeScalars(gym.make("relrl/SharedAttention-v1", max_steps=500), folder)
    model = make_model(args.algo, env, args.seed)
    model.set_logger(configure(str(folder), ["csv"]))
    before = cgi_of(model, args.seed)
    model.learn(total_timesteps=args.steps)
    after = cgi_of(model, args.seed)
    env.close()
    episodes = env.episodes
    print(f"{args.algo.upper()}, {args.steps:,} time units ({len(episodes)} episodes): CGI "
          f"{before:.2f} untrained -> {after:.2f} trained (the paper's protocol, 10 runs); "
          f"the last episode's CGI while learning {episodes[-1]['cgi']:.2f}; "
          f"TensorBoard: tensorboard --logdir {args.logdir}")
    result = {"algo": args.algo, "cgi_before": before, "cgi_after": after,
              "episodes": len(episodes), "folder": str(folder)}
    if args.check and after < before + 0.1:
        print(f"check failed: the CGI rose by {after - before:.2f}, less than 0.1",
              file=sys.stderr)
        sys.exit(1)
    return result


if __name__ == "__main__":
    main()
