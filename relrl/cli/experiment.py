"""``relrl experiment sis``: reproduce the paper's Experiment 1 with one command."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from relrl.outdir import add_out_options

HELP = ("reproduce the paper's experiments (sis: Experiment 1, the paper's three learners and "
        "tg in the simulator)")
EXAMPLE = "relrl experiment sis --quick --out runs/exp1-quick"


def _param(text: str) -> tuple[str, str, float]:
    try:
        key, value = text.split("=", 1)
        learner, name = key.split(".", 1)
        return learner, name, float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"bad --param {text!r}: use LEARNER.NAME=NUMBER, e.g. etg.alpha=0.3") from None


def _caregiver_param(text: str) -> tuple[str, object]:
    try:
        key, value = text.split("=", 1)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"bad --caregiver-param {text!r}: use NAME=VALUE, e.g. reliability=0.7") from None
    try:
        return key, json.loads(value)
    except json.JSONDecodeError:
        return key, value


def _places(option: str, text: str | None) -> list[str] | None:
    """The toy places of ``--train-places`` / ``--eval-places`` (None when not given)."""
    from relrl.errors import ConfigError
    from relrl.sim.errors import did_you_mean
    from relrl.sim.places import TOY_PLACES

    if text is None:
        return None
    places = [p.strip() for p in text.split(",") if p.strip()]
    if not places:
        raise ConfigError(f"{option} needs at least one place ({', '.join(TOY_PLACES)})")
    for p in places:
        if p not in TOY_PLACES:
            raise ConfigError(f"{option}: unknown toy place {p!r}{did_you_mean(p, TOY_PLACES)} "
                              f"(places: {', '.join(TOY_PLACES)})")
    return list(dict.fromkeys(places))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl experiment``."""
    parser.add_argument("name", choices=["sis"], help="which experiment")
    parser.add_argument("--learners", default="contingency,qlearning,etg,tg",
                        help="comma-separated learners (default: all four)")
    parser.add_argument("--points", type=int, default=None,
                        help="evaluation points after the first (default 20; --quick: 4)")
    parser.add_argument("--eval-runs", type=int, default=None,
                        help="evaluation runs per point (default 20; --quick: 5)")
    parser.add_argument("--eval-steps", type=int, default=500, help="time units per run")
    parser.add_argument("--block", type=int, default=500,
                        help="learning time units between evaluations (default 500)")
    parser.add_argument("--seeds", default="0", help="comma-separated seeds (default 0)")
    parser.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1),
                        help="worker processes, one Prolog engine each (default: up to 2)")
    parser.add_argument("--caregiver", default="paper", help="caregiver model (default paper)")
    parser.add_argument("--caregiver-param", type=_caregiver_param, action="append", default=[],
                        metavar="NAME=VALUE", help="override a caregiver parameter (repeatable)")
    parser.add_argument("--param", type=_param, action="append", default=[],
                        metavar="LEARNER.NAME=X", help="learner parameter (repeatable)")
    parser.add_argument("--eval-policy", choices=["behaviour", "greedy"], default="behaviour",
                        help="evaluate the robot's behaviour (exploration kept, the default) "
                             "or the greedy policy")
    parser.add_argument("--train-places", default=None, metavar="P,P,...",
                        help="toy places while learning, e.g. left,left_down,down (default: "
                             "all); the others are held out")
    parser.add_argument("--eval-places", default=None, metavar="P,P,...",
                        help="toy places of the evaluation (default: all); with held-out "
                             "places the CGI is reported for trained and held-out apart")
    parser.add_argument("--domain", default=None, help="domain file (default sis.pl)")
    add_out_options(parser, default="runs/exp1",
                    what="output folder: results.json, CSVs, figures")
    parser.add_argument("--quick", action="store_true", help="a short run (under a minute)")


def build_config(args: argparse.Namespace):
    """The SISConfig the options describe."""
    from relrl.errors import ConfigError
    from relrl.experiments.sis import SISConfig
    from relrl.learners import LEARNERS
    from relrl.sim.caregiver import make_caregiver

    learners = [x.strip() for x in args.learners.split(",") if x.strip()]
    for name in learners:
        if name not in LEARNERS:
            raise ConfigError(f"unknown learner {name!r} in --learners "
                              f"(known: {', '.join(sorted(LEARNERS))})")
    try:
        seeds = [int(s) for s in args.seeds.split(",")]
    except ValueError:
        raise ConfigError(f"--seeds must be comma-separated integers, not {args.seeds!r}") \
            from None
    for seed in seeds:
        if seed < 0:
            raise ConfigError(f"--seeds: {seed} is negative; seeds are integers >= 0")
    config = SISConfig(learners=learners, seeds=seeds)
    config.points = args.points if args.points is not None else (4 if args.quick else 20)
    config.eval_runs = args.eval_runs if args.eval_runs is not None else (5 if args.quick else 20)
    config.eval_steps = args.eval_steps
    config.block = args.block
    for what, value in [("--points", config.points), ("--eval-runs", config.eval_runs),
                        ("--eval-steps", config.eval_steps), ("--block", config.block)]:
        if value < 1:
            raise ConfigError(f"{what} must be at least 1, not {value}")
    config.eval_policy = args.eval_policy
    config.caregiver = args.caregiver
    config.caregiver_params.update(dict(args.caregiver_param))
    make_caregiver(config.caregiver, config.caregiver_params)  # validate now, not in a worker
    for learner, name, value in args.param:
        if learner not in learners:
            raise ConfigError(f"--param {learner}.{name}: {learner} is not among --learners")
        config.learner_params.setdefault(learner, {})[name] = value
    from relrl.learners import make_learner

    for learner in learners:
        make_learner(learner, **config.learner_params.get(learner, {}))  # validate
    config.train_places = _places("--train-places", args.train_places)
    config.eval_places = _places("--eval-places", args.eval_places)
    if args.domain:
        if not Path(args.domain).exists():
            raise ConfigError(f"--domain {args.domain}: no such file")
        config.domain = str(Path(args.domain).resolve())
    if args.workers < 1:
        raise ConfigError(f"--workers must be at least 1, not {args.workers}")
    return config


def run(args: argparse.Namespace) -> int:
    """Run the experiment, write the outputs, print the summary."""
    from relrl.experiments.main import run_sis
    from relrl.experiments.report import summary_table
    from relrl.outdir import OutDir

    config = build_config(args)
    with OutDir.claim(args.out, command=args.command_line, overwrite=args.overwrite,
                      default="runs/exp1") as out:
        results, files = run_sis(config, out.path, workers=args.workers)
        out.status = "complete"
    print(summary_table(results["summary"]))
    print(f"\nwrote {len(files)} files to {out.path}/:")
    for f in files:
        print(f"  {f}")
    return 0
