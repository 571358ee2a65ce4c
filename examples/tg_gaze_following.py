"""The tg learner learns gaze following in the Social Interactive Simulator and shows it.

Run it from the repository root (about a minute on an idle machine):

    .venv/bin/python examples/tg_gaze_following.py [--steps 10000] [--seed 0]
                                                   [--train-places left,left_down,down]
                                                   [--policy tg-sis.pl]

The robot learns with Experiment 1's caregiver (``relrl experiment sis``), then the script
prints the learned first-order tree, its memory in the paper's positions, the saved policy's
rules (Prolog a person reads and plain swipl consults), and what the greedy policy does when
the caregiver looks at each place — including places that never held a toy while learning
when ``--train-places`` is given.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from relrl.experiments.sis import DEFAULT_DOMAIN
from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent, Interaction
from relrl.sim.caregiver import make_caregiver
from relrl.sim.places import TOY_PLACES
from relrl.sim.sis import SharedAttentionEnv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=10_000, help="learning time units")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--train-places", default=None,
                        help="toy places while learning (default: all five)")
    parser.add_argument("--policy", default="tg-sis.pl", help="where to save the policy")
    args = parser.parse_args()

    params: dict = {}                                # Experiment 1's caregiver (the default)
    if args.train_places:
        params["placement"] = {p: 1.0 for p in args.train_places.split(",")}
    with KnowledgeBase(DEFAULT_DOMAIN) as kb:
        agent = Agent(kb, make_learner("tg"), seed=args.seed)
        env = SharedAttentionEnv(make_caregiver("paper", params), max_steps=None,
                                 record_trace=False)
        learning = Interaction(env, agent)
        learning.reset(seed=args.seed)
        learning.run(args.steps, keep=False)
        agent.end_episode()

        print(f"tg after {args.steps} time units (seed {args.seed}):\n")
        print(agent.learner.tree())
        size = agent.learner.size()
        print(f"memory: {size['positions']} positions ({size['nodes']} nodes, "
              f"{size['entries']} stored Q values); split statistics: "
              f"{size['statistics']} numbers for {size['candidates']} candidate tests\n")

        path = agent.learner.save(Path(args.policy))
        rules = path.read_text().split("one clause per leaf).\n", 1)[-1]
        print(f"the rules in {path}:\n{rules}")

        print("greedy choices, caregiver looking at each place:")
        for place in TOY_PLACES:
            out = agent.step([("see", "face"), ("pose", "face", place), ("at", "centre")],
                             learning=False, want=("explain",))
            path_text = "; ".join(
                f"{s['test']} {'yes' if s['holds'] else 'no'}"
                + (" (" + ", ".join(f"{k}={v}" for k, v in s["bindings"].items()) + ")"
                   if s["bindings"] else "")
                for s in out.explanation["path"])
            chosen = f"look({out.action[1]})"
            print(f"  gaze {place:<10} -> {chosen:<16}  via {path_text}")
            agent.end_episode()


if __name__ == "__main__":
    main()
