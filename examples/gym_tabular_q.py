"""Train an ordinary tabular Q-learning agent on relrl's Gymnasium task and evaluate it by the
paper's protocol — the way an outside lab would benchmark its own agent (docs/benchmark.md).

    .venv/bin/python examples/gym_tabular_q.py                        # v0, the paper's world
    .venv/bin/python examples/gym_tabular_q.py --places 9 --relational  # a larger world, keyed
                                                                        # on the relational view

The agent knows nothing of relrl: it sees the observation (a vector, or with --relational the
sorted tuple of relational facts), acts with an action index, and learns from the reward.
Only the evaluation uses relrl.sim.evaluate, so its CGI is comparable with relrl's learners.
"""

from __future__ import annotations

import argparse
from collections import defaultdict

import gymnasium as gym
import numpy as np

from relrl.sim import World, evaluate  # importing relrl.sim registers the environments
from relrl.sim.wrappers import RelationalObservation, RelationalView


def key(obs) -> tuple:
    """A hashable table key for a vector or a tuple of facts."""
    return tuple(obs.tolist()) if isinstance(obs, np.ndarray) else obs


def train(env: gym.Env, steps: int, seed: int, alpha: float = 0.1, gamma: float = 0.9,
          epsilon: float = 0.1) -> dict:
    """Epsilon-greedy one-step Q-learning for ``steps`` time units; returns the table."""
    rng = np.random.default_rng(seed)
    n = env.action_space.n
    q: dict = defaultdict(lambda: np.zeros(n))
    obs, _ = env.reset(seed=seed)
    for _ in range(steps):
        s = key(obs)
        a = int(rng.integers(n)) if rng.random() < epsilon else int(np.argmax(q[s]))
        obs, reward, terminated, truncated, _ = env.step(a)
        target = reward + (0.0 if terminated else gamma * np.max(q[key(obs)]))
        q[s][a] += alpha * (target - q[s][a])
        if terminated or truncated:
            obs, _ = env.reset()
    return q


def main(argv: list[str] | None = None) -> dict:
    """Train, evaluate, print and return the evaluation."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--places", type=int, default=5, help="toy places P (default 5)")
    parser.add_argument("--relational", action="store_true",
                        help="key the table on the relational view (RelationalObservation)")
    parser.add_argument("--steps", type=int, default=30_000, help="learning time units")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)

    world = {"places": args.places}
    env = gym.make("relrl/SharedAttention-v1", world=world, max_steps=None)
    if args.relational:
        env = RelationalObservation(env)
    q = train(env, args.steps, args.seed)
    n = env.action_space.n

    env.close()
    view = RelationalView(World(**world)) if args.relational else None

    def greedy(obs, info):
        state = view(info["percepts"]) if view is not None else key(obs)
        values = q.get(state)
        return int(np.argmax(values)) if values is not None else 0   # unseen: look at the face

    # the protocol of relrl's experiments: 10 runs x 500 time units, no learning
    result = evaluate(greedy, world=world, runs=10, steps=500, seed=args.seed, observation=1)
    if view is not None:
        view.close()
    print(f"tabular Q-learning, {args.steps:,} time units, P={args.places}"
          f"{', relational keys' if args.relational else ''}: {len(q):,} table rows "
          f"({len(q) * n:,} positions)")
    print(f"CGI {result.cgi_mean:.2f} ± {result.cgi_std:.2f} (Eq. 5 literally "
          f"{result.cgi_literal_mean:.2f}); eye contacts per run {result.eye_contacts_mean:.0f}")
    return {"cgi": result.cgi_mean, "cgi_literal": result.cgi_literal_mean, "rows": len(q)}


if __name__ == "__main__":
    main()
