"""``relrl evaluate POLICY --world WORLD.pl --task T``: act greedily on a saved policy, with no
learning, from start states of a file or drawn at given sizes; score against the optimum."""

from __future__ import annotations

import argparse
from pathlib import Path

from relrl.outdir import add_out_options

#: the files ``relrl evaluate`` writes in its folder.
OUTPUTS = ("results.json", "episodes.csv")

HELP = "act on a saved world policy (no learning) from given or drawn start states; score it"
EXAMPLE = ("relrl evaluate runs/stack/policy.pl --world examples/worlds/blocks.pl --task stack "
           "--sizes 10,20,50 --episodes 50\n"
           "  relrl evaluate runs/on/policy.pl --world examples/worlds/blocks.pl --task on "
           "--states my_states.pl --out runs/on-mine")

#: the columns of episodes.csv.
COLUMNS = ("size", "state", "where", "goal", "steps", "optimal", "reached", "of_optimal")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl evaluate``."""
    parser.add_argument("policy", metavar="POLICY",
                        help="a policy saved by relrl learn or relrl experiment worlds "
                             "(read as data)")
    parser.add_argument("--world", required=True, metavar="WORLD.pl",
                        help="the world file the policy was learned in (docs/worlds.md)")
    parser.add_argument("--task", default=None,
                        help="a task of the world: its name (stack, on) or an instance "
                             "(on(b1, b2)); default: the first the world declares")
    parser.add_argument("--states", default=None, metavar="FILE",
                        help="start states: a Prolog file, one term per state (a list of "
                             "facts, or state(Facts, Task)), or a .json list of lists of "
                             "facts as text; one episode from each")
    parser.add_argument("--sizes", default=None, metavar="N,N,...",
                        help="without --states: start states from the world's "
                             "initial_state/2 at these sizes (default: the world's "
                             "sizes(test, ...))")
    parser.add_argument("--episodes", type=int, default=100,
                        help="with --sizes: episodes per size (100)")
    parser.add_argument("--seed", type=int, default=0,
                        help="random seed: start states, a task's drawn goal, ties (0)")
    parser.add_argument("--actions", action="store_true",
                        help="keep each episode's actions in results.json")
    from relrl.cli.learn import add_rule_seconds

    add_rule_seconds(parser)
    add_out_options(parser, default="runs/evaluate",
                    what="output folder: results.json, episodes.csv")


def run(args: argparse.Namespace) -> int:
    """Check the options, evaluate, print a line per size, write the folder."""
    from relrl.cli.learn import _sizes
    from relrl.engine import policy_learner
    from relrl.errors import ConfigError
    from relrl.outdir import OutDir
    from relrl.worlds import World
    from relrl.worlds.evaluate import evaluate_policy, read_states

    world = Path(args.world)
    if not world.is_file():
        raise ConfigError(f"--world {args.world}: no such world file")
    from relrl.policy import not_a_policy_file

    if (problem := not_a_policy_file(args.policy)) is not None:
        raise ConfigError(f"{args.policy}: {problem}")
    if args.states is not None and args.sizes is not None:
        raise ConfigError("give --states or --sizes, not both")
    if args.episodes < 1:
        raise ConfigError(f"--episodes must be at least 1, not {args.episodes}")
    if args.seed < 0:
        raise ConfigError(f"--seed must be a whole number >= 0, not {args.seed}")
    with World(world, rule_seconds=args.rule_seconds) as w:
        problems = w.problems()
        if problems:
            raise ConfigError(f"{problems[0]} (and {len(problems) - 1} more: relrl check "
                              f"--world {args.world})" if len(problems) > 1 else problems[0])
        task = args.task or w.task_names()[0].split("(")[0]
        task_term = w.task(task)                     # validate all before the folder
        w.attach(w.learner(policy_learner(w.kb, args.policy)), args.seed, task_term)
        w.load_policy(args.policy)
        if args.states is not None:
            read_states(w, args.states, task_term)
        sizes = (_sizes(args.sizes, "--sizes") if args.sizes is not None
                 else [] if args.states is not None else w.test_sizes or w.train_sizes)
    with OutDir.claim(args.out, command=args.command_line, overwrite=args.overwrite,
                      default="runs/evaluate", outputs=OUTPUTS) as out:
        result = evaluate_policy(world, args.policy, task, sizes=sizes,
                                 episodes=args.episodes, states=args.states, seed=args.seed,
                                 actions=args.actions)
        files = _write(out.path, result)
        out.status = "complete"
    print(f"{result['learner']} policy on {task}, greedy, no learning:")
    for label, s in result["summary"].items():
        name = f"size {label:>3}" if label != "states" else f"{args.states}"
        opt = "-" if s["optimality"] is None else f"{s['optimality']:.3f}"
        print(f"  {name}: of optimal {opt}, reached {s['success']:.3f}, "
              f"{s['episodes']} episodes, steps {s['steps']:.2f}"
              + (f" (optimal {s['optimal_steps']:.2f})" if s["optimal_steps"] is not None
                 else "")
              + f", {s['cpu_seconds_per_episode']:.3f} s CPU per episode")
    print(f"wrote {', '.join(str(f) for f in files)}")
    return 0


def _write(out: Path, result: dict) -> list[Path]:
    import csv
    import io

    from relrl.outdir import write_atomic, write_json_atomic

    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(COLUMNS)
    for row in result["rows"]:
        w.writerow(["" if row[k] is None else row[k] for k in COLUMNS])
    return [write_json_atomic(out / "results.json", result),
            write_atomic(out / "episodes.csv", buf.getvalue())]
