"""``relrl experiment sis|scaling``: Experiment 1, and the scaling benchmark, with one command."""

from __future__ import annotations

import argparse
import json
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from relrl.cli.recorded import add_config_option, apply_record, finish_record
from relrl.outdir import add_out_options

HELP = ("run the experiments (sis: the paper's Experiment 1, with relrl's relational learner tg "
        "beside the paper's three; scaling: every learner in worlds that grow, with zero-shot "
        "transfer; worlds: tasks of worlds written in Prolog, blocks world first)")
EXAMPLE = ("relrl experiment sis --quick --out runs/exp1-quick\n"
           "  relrl experiment sis --config runs/exp1-quick/results.json --out runs/exp1-again\n"
           "  relrl experiment scaling --quick --out runs/scaling-quick\n"
           "  relrl experiment worlds --quick --out runs/worlds-quick")

#: ``--quick`` settings of the scaling benchmark (under 5 minutes on 2 cores).
QUICK_SCALING = {"seeds": "0", "budget": 20_000, "block": 2_000, "eval_runs": 4,
                 "eval_steps": 300, "transfer_sizes": "5,9"}


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


def _common(p: argparse.ArgumentParser, *, default_seeds: str) -> None:
    p.add_argument("--learners", default=None,
                   help="comma-separated learners (default: every learner of the "
                        "simulator's domains)")
    p.add_argument("--seeds", default=None, help=f"comma-separated seeds (default "
                                                 f"{default_seeds})")
    p.add_argument("--eval-runs", type=int, default=None, help="evaluation runs per point")
    p.add_argument("--eval-steps", type=int, default=None, help="time units per run")
    p.add_argument("--block", type=int, default=None,
                   help="learning time units between evaluations")
    p.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1),
                   help="worker processes, one Prolog engine each (default: up to 2)")
    p.add_argument("--engine", choices=["local", "ray"], default="local",
                   help="where the jobs run: local worker processes (default) or a Ray "
                        "cluster (pip install 'relrl[ray]')")
    p.add_argument("--address", default=None,
                   help="with --engine ray: the cluster to join (ray://HEAD:10001, "
                        "HOST:6379 or auto); default: a local Ray instance with --workers "
                        "CPUs")
    p.add_argument("--caregiver", default=None,
                   help="caregiver model (default paper, or the preset's)")
    p.add_argument("--caregiver-param", type=_caregiver_param, action="append", default=[],
                   metavar="NAME=VALUE", help="override a caregiver parameter (repeatable)")
    p.add_argument("--param", type=_param, action="append", default=[],
                   metavar="LEARNER.NAME=X", help="learner parameter (repeatable)")
    p.add_argument("--eval-policy", choices=["behaviour", "greedy"], default="behaviour",
                   help="evaluate the robot's behaviour (exploration kept, the default) "
                        "or the greedy policy")
    p.add_argument("--timeout", type=float, default=60.0, metavar="SECONDS",
                   help="seconds one control step may run before the run stops, naming the "
                        "rule (default 60)")
    p.add_argument("--quick", action="store_true", help="a short run")
    add_config_option(p)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the subcommands and options of ``relrl experiment``."""
    sub = parser.add_subparsers(dest="name", metavar="EXPERIMENT", required=True,
                                parser_class=type(parser))
    sis = sub.add_parser("sis", help="the paper's Experiment 1 (the learners in the SIS)",
                         description="The paper's Experiment 1: learning curves (CGI), eye "
                                     "contacts and memory of each learner in the simulator.",
                         epilog="examples:\n"
                                "  relrl experiment sis --out runs/exp1\n"
                                "  relrl experiment sis --preset paper-2012 --learners "
                                "contingency,qlearning,etg --seeds 0,1,2,3,4 --out "
                                "runs/paper-2012\n"
                                "  relrl experiment sis --config runs/exp1/results.json --out "
                                "runs/exp1-again",
                         formatter_class=argparse.RawDescriptionHelpFormatter)
    _common(sis, default_seeds="0")
    from relrl.experiments.sis import PRESETS

    sis.add_argument("--preset", default=None, choices=sorted(PRESETS),
                     help="start from a named setting; the other options override it. "
                          + " ".join(f"{k}: {v['doc']}." for k, v in PRESETS.items())
                          + " Default: relrl's fixed task (docs/experiment1.md)")
    sis.add_argument("--points", type=int, default=None,
                     help="evaluation points after the first (default 20; --quick: 4)")
    sis.add_argument("--train-places", default=None, metavar="P,P,...",
                     help="toy places while learning, e.g. left,left_down,down (default: "
                          "all); the others are held out")
    sis.add_argument("--eval-places", default=None, metavar="P,P,...",
                     help="toy places of the evaluation (default: all); with held-out "
                          "places the CGI is reported for trained and held-out apart")
    sis.add_argument("--domain", default=None, help="domain file (default sis.pl)")
    add_out_options(sis, default="runs/exp1", what="output folder: results.json, CSVs, figures")
    sc = sub.add_parser("scaling", help="every learner in worlds that grow; transfer",
                        description="Time to CGI >= 0.9, final CGI, memory and steps/s of "
                                    "every learner as the world grows (P toy places), and "
                                    "zero-shot transfer to places never trained on.",
                        epilog="examples:\n"
                               "  relrl experiment scaling --quick --out runs/scaling-quick\n"
                               "  relrl experiment scaling --learners tg --sizes "
                               "5,9,17,33,65,129 --out runs/scaling-tg\n"
                               "  relrl experiment scaling --learners tg --sizes 5 --transfer "
                               "sizes --transfer-sizes 9,33,129 --out runs/transfer",
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    _common(sc, default_seeds="0,1,2")
    sc.add_argument("--sizes", default="5,9,17,33", help="world sizes P (default 5,9,17,33)")
    sc.add_argument("--world", default="", metavar="NAME=VALUE,...",
                    help="the worlds' other fields: colours, kinds, toys, scene, field "
                         "(e.g. colours=3,scene=true)")
    sc.add_argument("--budget", type=int, default=None,
                    help="learning time units at most (default 60000; --quick 20000)")
    sc.add_argument("--threshold", type=float, default=0.9, help="the CGI to reach (0.9)")
    sc.add_argument("--patience", type=int, default=2, help="stop after this many "
                    "evaluations at or above the threshold (0: learn the whole budget)")
    sc.add_argument("--transfer", choices=["places", "kinds", "sizes", "none"],
                    default="places",
                    help="hold out places (default) or toy kinds; sizes: learn at "
                         "--transfer-from places, then act with no learning in the worlds of "
                         "--transfer-sizes; none: no transfer jobs")
    sc.add_argument("--transfer-sizes", default=None,
                    help="sizes with transfer jobs, or with --transfer sizes the worlds the "
                         "policy is evaluated in (default: all; --quick: 5,9)")
    sc.add_argument("--transfer-from", type=int, default=5,
                    help="with --transfer sizes: the world size learned in (default 5)")
    sc.add_argument("--holdout", type=float, default=0.4,
                    help="share of places (or kinds) held out (default 0.4)")
    add_out_options(sc, default="runs/scaling",
                    what="output folder: results.json, CSVs, figures, domains")
    _add_worlds(sub)


def _add_worlds(sub) -> None:
    w = sub.add_parser("worlds", help="tasks of worlds written in Prolog (blocks world)",
                       description="Learning curves, evaluation on other sizes with no "
                                   "further learning, memory and step cost of the learners "
                                   "of worlds on tasks of worlds written in Prolog; the "
                                   "worlds' stated optimum "
                                   "checked by search.",
                       epilog="examples:\n"
                              "  relrl experiment worlds --quick --out runs/worlds-quick\n"
                              "  relrl experiment worlds --tasks stack,unstack,on --seeds "
                              "0,1,2 --out runs/worlds",
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    w.add_argument("--worlds", default=None, metavar="FILE,FILE",
                   help="world files (default: the shipped blocks.pl and blocks_moves.pl)")
    w.add_argument("--tasks", default=None,
                   help="comma-separated tasks, each run in the worlds that declare it "
                        "(default: every task of each world)")
    w.add_argument("--learners", default=None,
                   help="comma-separated learners (default: every learner of worlds)")
    w.add_argument("--seeds", default=None,
                   help="comma-separated seeds or ranges, 0-9 (default 0,1,2)")
    w.add_argument("--sizes", default=None,
                   help="training sizes of every world (default: each world's sizes(train, "
                        "...), else 3,4,5)")
    w.add_argument("--test-sizes", default=None,
                   help="sizes evaluated with no further learning, in every world (default: "
                        "each world's sizes(test, ...), else 10,20,50)")
    w.add_argument("--episodes", type=int, default=None,
                   help="learning episodes per job (default 1000; --quick 200)")
    w.add_argument("--block", type=int, default=None,
                   help="learning episodes between evaluations (default 100; --quick 50)")
    w.add_argument("--eval-episodes", type=int, default=None,
                   help="greedy episodes per evaluation (default 100; --quick 30)")
    w.add_argument("--param", type=_param, action="append", default=[],
                   metavar="LEARNER.NAME=X", help="learner parameter (repeatable)")
    w.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1),
                   help="worker processes, one Prolog engine each (default: up to 2)")
    w.add_argument("--engine", choices=["local", "ray"], default="local",
                   help="local worker processes (default) or a Ray cluster")
    w.add_argument("--address", default=None, help="with --engine ray: the cluster to join")
    from relrl.cli.learn import add_restart_options, add_rule_seconds

    add_restart_options(w)
    add_rule_seconds(w)
    w.add_argument("--quick", action="store_true",
                   help="a short run: seed 0, learner tg, 200 episodes in blocks of 50, 30 "
                        "greedy episodes per evaluation (each overridden by its option)")
    w.add_argument("--no-speed", action="store_true",
                   help="skip each job's step-cost measurement by size")
    add_out_options(w, default="runs/worlds",
                    what="output folder: results.json, CSVs, figures")


def _seeds(text: str) -> list[int]:
    """``--seeds``: comma-separated seeds and ranges (``0-9``)."""
    from relrl.errors import ConfigError

    seeds: list[int] = []
    for part in (p.strip() for p in text.split(",") if p.strip()):
        lo, sep, hi = part.partition("-")
        try:
            seeds += list(range(int(lo), int(hi) + 1)) if sep and lo else [int(part)]
        except ValueError:
            raise ConfigError(f"--seeds {text!r}: {part!r} is not a seed or a range "
                              "such as 0-9") from None
    return seeds


def _ints(text: str, what: str) -> list[int]:
    from relrl.errors import ConfigError

    try:
        values = [int(s) for s in text.split(",")]
    except ValueError:
        raise ConfigError(f"{what} must be comma-separated integers, not {text!r}") from None
    if not values:
        raise ConfigError(f"{what} is empty")
    return values


#: the most evaluation points, runs, time units or learning units an option may ask for (more
#: is no run that ends; numpy refuses arrays that large).
MAX_COUNT = 10**9


def _distinct(option: str, names: list[str], why: str = "each would count twice") -> None:
    """Refuse a name given twice in a comma-separated option (one line naming it)."""
    from relrl.errors import ConfigError

    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ConfigError(f"{option} names {', '.join(twice)} twice ({why})")


def _check_common(args: argparse.Namespace, config) -> None:
    """Validate and copy the options both experiments share into ``config``."""
    from relrl.errors import ConfigError
    from relrl.learners import DOMAINS, learners, make_learner

    learners_known = learners(DOMAINS)
    names = ",".join(learners_known) if args.learners is None else args.learners
    learners = [x.strip() for x in names.split(",") if x.strip()]
    for name in learners:
        if name not in learners_known:
            raise ConfigError(f"unknown learner {name!r} in --learners "
                              f"(known: {', '.join(sorted(learners_known))})")
    if not learners:
        raise ConfigError("--learners is empty")
    _distinct("--learners", learners)
    config.learners = learners
    for what, value in [("--eval-runs", config.eval_runs), ("--eval-steps", config.eval_steps),
                        ("--block", config.block)]:
        if value < 1:
            raise ConfigError(f"{what} must be at least 1, not {value}")
        if value > MAX_COUNT:
            raise ConfigError(f"{what} must be at most {MAX_COUNT:,}, not {value}")
    if len(set(config.seeds)) != len(config.seeds) or any(s < 0 for s in config.seeds):
        raise ConfigError(f"--seeds must be distinct whole numbers >= 0, not {args.seeds!r}")
    config.eval_policy = args.eval_policy
    if args.caregiver is not None:
        config.caregiver = args.caregiver
    config.caregiver_params.update(dict(args.caregiver_param))
    for learner, name, value in args.param:
        if learner not in learners:
            raise ConfigError(f"--param {learner}.{name}: {learner} is not among --learners")
        config.learner_params.setdefault(learner, {})[name] = value
    for learner in learners:
        make_learner(learner, **config.learner_params.get(learner, {}))  # validate
    if args.workers < 1:
        raise ConfigError(f"--workers must be at least 1, not {args.workers}")
    if args.address is not None and args.engine != "ray":
        raise ConfigError("--address applies to --engine ray only")
    from relrl.shell import check_timeout

    config.timeout = check_timeout(args.timeout, "--timeout")


def build_config(args: argparse.Namespace):
    """The SISConfig the options of ``relrl experiment sis`` describe."""
    from relrl.errors import ConfigError
    from relrl.experiments.sis import SISConfig
    from relrl.sim.caregiver import make_caregiver

    record = apply_record(args, "sis")
    config = SISConfig.from_preset(args.preset, seeds=_ints(
        args.seeds if args.seeds is not None else "0", "--seeds"))
    config.points = args.points if args.points is not None else (4 if args.quick else 20)
    config.eval_runs = args.eval_runs if args.eval_runs is not None else (5 if args.quick else 20)
    config.eval_steps = args.eval_steps if args.eval_steps is not None else 500
    config.block = args.block if args.block is not None else 500
    if not 1 <= config.points <= MAX_COUNT:
        raise ConfigError(f"--points must be 1 to {MAX_COUNT:,}, not {config.points}")
    _check_common(args, config)
    config.learner_params = {k: v for k, v in config.learner_params.items()
                             if k in config.learners}
    make_caregiver(config.caregiver, config.caregiver_params)  # validate now, not in a worker
    make_caregiver(config.caregiver, {**config.caregiver_params,
                                      **config.eval_caregiver_params})
    config.train_places = _places("--train-places", args.train_places)
    config.eval_places = _places("--eval-places", args.eval_places)
    if args.domain:
        if not Path(args.domain).is_file():
            raise ConfigError(f"--domain {args.domain}: no such file")
        config.domain = str(Path(args.domain).resolve())
    return finish_record(config, record)


def build_scaling_config(args: argparse.Namespace):
    """The ScalingConfig the options of ``relrl experiment scaling`` describe."""
    from relrl.errors import ConfigError
    from relrl.experiments.scaling import ScalingConfig
    from relrl.sim.world import World

    record = apply_record(args, "scaling")
    quick = QUICK_SCALING if args.quick else {}
    config = ScalingConfig(seeds=_ints(args.seeds if args.seeds is not None
                                       else quick.get("seeds", "0,1,2"), "--seeds"))
    config.sizes = _ints(args.sizes, "--sizes")
    for name in ("budget", "block", "eval_runs", "eval_steps"):
        value = getattr(args, name)
        if value is None:
            value = quick.get(name, getattr(config, name))
        setattr(config, name, value)
    _check_common(args, config)
    if config.budget < config.block:
        raise ConfigError(f"--budget ({config.budget}) must be at least --block "
                          f"({config.block})")
    if math.isnan(args.threshold) or not 0 < args.threshold <= 1:
        raise ConfigError(f"--threshold must be in (0, 1], not {args.threshold}")
    config.threshold = args.threshold
    if args.patience < 0:
        raise ConfigError(f"--patience must be 0 or more, not {args.patience}")
    config.patience = args.patience
    world = World.parse(args.world)
    if "places" in {k.split("=")[0].strip() for k in args.world.split(",")}:
        raise ConfigError("--world sets the other fields; give the places with --sizes")
    config.world = {k: v for k, v in world.to_dict().items() if k != "places"}
    if args.transfer == "places" and "placement" in config.caregiver_params:
        raise ConfigError("--transfer places sets the placement weights itself; drop "
                          "--caregiver-param placement or use --transfer none")
    for size in config.sizes:
        try:
            config.world_of(size).caregiver_params(config.caregiver_params, config.caregiver)
        except ConfigError as exc:
            raise ConfigError(f"--sizes {size}: {exc}") from None
    config.transfer = args.transfer
    transfer_sizes = (args.transfer_sizes if args.transfer_sizes is not None
                      else quick.get("transfer_sizes"))
    config.transfer_sizes = (_ints(transfer_sizes, "--transfer-sizes")
                             if transfer_sizes is not None else list(config.sizes))
    if math.isnan(args.holdout) or not 0 < args.holdout < 1:
        raise ConfigError(f"--holdout must be between 0 and 1, not {args.holdout}")
    config.holdout = args.holdout
    if config.transfer == "sizes":
        from relrl.errors import UserError

        for flag, size in [("--transfer-from", args.transfer_from),
                           *(("--transfer-sizes", s) for s in config.transfer_sizes)]:
            try:
                config.world_of(size).caregiver_params(config.caregiver_params,
                                                       config.caregiver)
            except UserError as exc:
                raise ConfigError(f"{flag} {size}: {exc}") from None
    config.transfer_from = args.transfer_from
    if config.transfer == "kinds" and world.kinds < 2:
        raise ConfigError("--transfer kinds needs at least 2 toy kinds: add --world kinds=4")
    return finish_record(config, record)


def run(args: argparse.Namespace) -> int:
    """Check everything, claim the output folder, run the experiment, print the summary.

    ``kill -USR1 PID`` prints the stack of every thread to stderr (for a sweep that seems
    stuck); Ctrl-C, SIGTERM or SIGHUP stops it keeping what finished."""
    import faulthandler
    import io
    import signal
    import sys

    if hasattr(signal, "SIGUSR1") and sys.__stderr__ is not None:
        try:
            faulthandler.register(signal.SIGUSR1, file=sys.__stderr__, all_threads=True)
        except (ValueError, OSError, io.UnsupportedOperation):
            pass  # no real stderr (embedded): no stack dumps, nothing else changes
    from relrl.experiments import sis as sis_experiment
    from relrl.experiments.results import OUTPUTS, summary_table

    if args.name == "scaling":
        return _run_scaling(args)
    if args.name == "worlds":
        return _run_worlds(args)
    from relrl.experiments.sis import claims_table

    config = build_config(args)
    print(f"setting: {config.setting()}")
    results, files, out, signum = _claimed_run(args, "runs/exp1", OUTPUTS, sis_experiment.run_sis,
                                               config)
    print(summary_table(results["summary"]))
    if any(c["held"] is not None for c in results.get("claims", {}).values()):
        print("\nthe paper's claims (docs/experiment1.md):")
        print(claims_table(results["claims"]))
    return _finish(results, files, out, signum)


def _claimed_run(args: argparse.Namespace, default: str, outputs: Any,
                 run: Callable[..., tuple[dict, list]], config: Any
                 ) -> tuple[dict, list, Path, int | None]:
    """Run an experiment into the --out folder it claims (marked partial or complete),
    with Ctrl-C, SIGTERM and SIGHUP ending it gracefully: its results, the files written,
    the folder and the signal that stopped it, if one did."""
    from relrl.experiments.runner import command_signals
    from relrl.outdir import OutDir

    with command_signals() as signals, \
            OutDir.claim(args.out, command=args.command_line, overwrite=args.overwrite,
                         default=default, outputs=outputs) as out:
        results, files = run(config, out.path, workers=args.workers, engine=args.engine,
                             address=args.address)
        out.status = "partial" if results.get("partial") else "complete"
    return results, files, out.path, signals.signum


def _run_scaling(args: argparse.Namespace) -> int:
    from relrl.experiments.scaling_report import OUTPUTS, run_scaling, scaling_table

    results, files, out, signum = _claimed_run(args, "runs/scaling", OUTPUTS, run_scaling,
                                               build_scaling_config(args))
    timing = json.loads((out / "timing.json").read_text())
    print(scaling_table(results, timing))
    return _finish(results, files, out, signum)


def build_worlds_config(args: argparse.Namespace):
    """The WorldsConfig the options of ``relrl experiment worlds`` describe."""
    from relrl.errors import ConfigError
    from relrl.learners import WORLDS, learners, make_world_learner
    from relrl.resources import examples_dir
    from relrl.terms import split_terms
    from relrl.worlds import World
    from relrl.worlds.experiment import WorldsConfig

    seeds = args.seeds if args.seeds is not None else ("0" if args.quick else "0,1,2")
    config = WorldsConfig(seeds=_seeds(seeds))
    if not config.seeds:
        raise ConfigError(f"--seeds must name at least one seed, not {seeds!r}")
    if args.worlds is not None:
        config.worlds = [w.strip() for w in args.worlds.split(",") if w.strip()]
        if not config.worlds:
            raise ConfigError(f"--worlds must name at least one world file, not "
                              f"{args.worlds!r}")
    else:
        folder = examples_dir() / "worlds"
        config.worlds = [str(folder / "blocks.pl"), str(folder / "blocks_moves.pl")]
    for i, path in enumerate(config.worlds):
        if not Path(path).is_file():
            raise ConfigError(f"--worlds {path}: no such world file")
        config.worlds[i] = str(Path(path).resolve())
    _distinct("--worlds", [Path(w).name for w in config.worlds],
              "results are kept by the world's file name")
    config.tasks = split_terms(args.tasks) if args.tasks is not None else []
    config.speed = not args.no_speed
    names = (args.learners if args.learners is not None
             else "tg" if args.quick else ",".join(learners(WORLDS)))
    config.learners = [x.strip() for x in names.split(",") if x.strip()]
    _distinct("--tasks", config.tasks)
    _distinct("--learners", config.learners)
    for name in config.learners:
        if name not in learners(WORLDS):
            raise ConfigError(f"unknown learner {name!r} in --learners (learners of worlds: "
                              f"{', '.join(learners(WORLDS))})")
    if (args.tasks is not None and not config.tasks) or not config.learners:
        raise ConfigError("--tasks and --learners must name at least one each")
    given = {"train": _ints(args.sizes, "--sizes") if args.sizes is not None else None,
             "test": (_ints(args.test_sizes, "--test-sizes") if args.test_sizes is not None
                      else None)}
    if any(s < 1 for ss in given.values() if ss is not None for s in ss):
        raise ConfigError("sizes must be whole numbers >= 1")
    config.episodes = (args.episodes if args.episodes is not None
                       else 200 if args.quick else 1000)
    config.block = args.block if args.block is not None else 50 if args.quick else 100
    config.eval_episodes = (args.eval_episodes if args.eval_episodes is not None
                            else 30 if args.quick else 100)
    for what, value in [("--episodes", config.episodes), ("--block", config.block),
                        ("--eval-episodes", config.eval_episodes)]:
        if value < 1:
            raise ConfigError(f"{what} must be at least 1, not {value}")
    if len(set(config.seeds)) != len(config.seeds) or any(s < 0 for s in config.seeds):
        raise ConfigError(f"--seeds must be distinct whole numbers >= 0, not {args.seeds!r}")
    for learner, name, value in args.param:
        if learner not in config.learners:
            raise ConfigError(f"--param {learner}.{name}: {learner} is not among --learners")
        config.learner_params.setdefault(learner, {})[name] = value
    for learner in config.learners:
        make_world_learner(learner, **config.learner_params.get(learner, {}))  # validate
    config.rule_seconds = args.rule_seconds
    # a world that declares no sizes: WorldsConfig's (3-5, then 10, 20, 50)
    default = {"train": config.train_sizes, "test": config.test_sizes}
    from relrl.cli.learn import check_restart_options

    check_restart_options(args)
    config.restarts, config.check_episodes = args.restarts, args.check_episodes
    for path in config.worlds:
        with World(path, rule_seconds=config.rule_seconds) as world:
            problems = world.problems()
            if problems:
                raise ConfigError("\n".join([*problems, f"{len(problems)} problem(s) in "
                                             f"{path} (relrl check --world {path})"]))
            names = [t.split("(")[0] for t in world.task_names()]
            if args.tasks is None:
                config.world_tasks[path] = names
            else:
                config.world_tasks[path] = [t for t in config.tasks
                                            if t.split("(")[0] in names]
                for task in config.world_tasks[path]:
                    world.task(task)
            declared = world.declared_sizes
            config.world_sizes[path] = {k: given[k] or declared[k] or default[k]
                                        for k in ("train", "test")}
            for task in config.world_tasks[path]:
                world.check_instance(task, [*config.world_sizes[path]["train"],
                                            *config.world_sizes[path]["test"]])
    config.train_sizes = sorted({s for ss in config.world_sizes.values() for s in ss["train"]})
    config.test_sizes = sorted({s for ss in config.world_sizes.values() for s in ss["test"]})
    if args.tasks is None:
        config.tasks = list(dict.fromkeys(t for ts in config.world_tasks.values() for t in ts))
    missing = [t for t in config.tasks
               if not any(t in ts for ts in config.world_tasks.values())]
    if missing:
        raise ConfigError(f"--tasks {','.join(missing)}: no such task in any world of "
                          "--worlds")
    if args.workers < 1:
        raise ConfigError(f"--workers must be at least 1, not {args.workers}")
    return config


def _run_worlds(args: argparse.Namespace) -> int:
    from relrl.report import worlds_cost_table
    from relrl.worlds.experiment import OUTPUTS, run_worlds, worlds_table

    results, files, out, signum = _claimed_run(args, "runs/worlds", OUTPUTS, run_worlds,
                                               build_worlds_config(args))
    print(worlds_table(results))
    timing = json.loads((out / "timing.json").read_text())
    if any(t.get("step_cost_by_size") for t in timing.get("jobs", [])):
        print("\ncost (process CPU time; a learning step at each size from the learned policy, "
              "the median of five rounds):\n")
        print(worlds_cost_table(timing))
    return _finish(results, files, out, signum)


def _finish(results: dict, files: list, out: Path, signum: int | None) -> int:
    """Say what was written; 128 + N when signal N stopped the experiment (or came while
    its outputs were being written)."""
    import signal

    print(f"\nwrote {len(files)} files to {out}/:")
    for f in files:
        print(f"  {f}")
    if results.get("partial"):
        by = results.get("interrupted_by", "a signal")
        print(f"stopped by {by}: the results are partial (every finished evaluation point "
              "is kept)")
        return 128 + (signal.Signals[by].value if by in signal.Signals.__members__
                      else signum or signal.SIGINT)
    if signum is not None:
        print(f"{signal.Signals(signum).name} came as the outputs were written: they are "
              "complete")
        return 128 + signum
    return 0
