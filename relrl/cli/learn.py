"""``relrl learn WORLD.pl``: learn a task of a world written in Prolog, evaluate it on other
sizes with no further learning."""

from __future__ import annotations

import argparse
import json
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from relrl.outdir import add_out_options

#: the files and folders ``relrl learn --out DIR`` writes (checked for links before it runs).
OUTPUTS = ("results.json", "timing.json", "curve.csv", "policy.pl", "traces.jsonl", "replay/")

HELP = "learn a task of a world written in Prolog (blocks world ...) and evaluate the policy"
EXAMPLE = ("relrl learn examples/worlds/blocks.pl --learner tg --task stack --episodes 500\n"
           "  relrl learn examples/worlds/blocks.pl --task on --size 4 --eval-sizes 6,8 "
           "--out runs/blocks-on")


def _sizes(text: str, option: str) -> list[int]:
    from relrl.errors import ConfigError

    try:
        sizes = [int(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise ConfigError(f"{option} must be comma-separated whole numbers, not "
                          f"{text!r}") from None
    if not sizes or any(s < 1 for s in sizes):
        raise ConfigError(f"{option} must be whole numbers >= 1, not {text!r}")
    return sizes


def _seconds(text: str) -> float:
    """A positive, finite number of seconds (``--rule-seconds``)."""
    import math

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a positive number of seconds, not {text!r}")
    return value


def add_rule_seconds(parser: argparse.ArgumentParser) -> None:
    """``--rule-seconds S``: how long a rule of a world may run (relrl learn, relrl check
    --world, relrl experiment worlds)."""
    from relrl.worlds.world import RULE_SECONDS

    parser.add_argument("--rule-seconds", type=_seconds, default=RULE_SECONDS, metavar="S",
                        help=f"stop a rule of the world that runs S seconds, naming it "
                             f"(default {RULE_SECONDS:g}; a batch of episodes runs as long "
                             "as its steps end)")


def _param(text: str) -> tuple[str, float]:
    try:
        key, value = text.split("=", 1)
        return key.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"bad --param {text!r}: use NAME=NUMBER, e.g. gamma=1") from None


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl learn``."""
    parser.add_argument("world", metavar="WORLD.pl", help="the world file (docs/worlds.md)")
    parser.add_argument("--learner", default="tg",
                        help="a learner of worlds (default tg, relational; docs/worlds.md "
                             "describes each)")
    parser.add_argument("--task", default=None,
                        help="a task of the world: its name (stack, on) or an instance "
                             "(on(b1, b2)); default: the first the world declares")
    parser.add_argument("--size", type=int, default=None,
                        help="learn on worlds of this size only")
    parser.add_argument("--sizes", default=None, metavar="N,N,...",
                        help="learn on these sizes, one drawn per episode (default: the "
                             "world's sizes(train, ...), else 3)")
    parser.add_argument("--eval-sizes", default=None, metavar="N,N,...",
                        help="evaluate on these sizes with no further learning (default: "
                             "the world's sizes(test, ...))")
    parser.add_argument("--episodes", type=int, default=500,
                        help="learning episodes (500; 0 with --policy: evaluate it only)")
    parser.add_argument("--block", type=int, default=None,
                        help="learning episodes between evaluations (default episodes/10)")
    parser.add_argument("--eval-episodes", type=int, default=100,
                        help="greedy episodes per evaluation and per evaluation size (100)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (0)")
    add_restart_options(parser)
    add_rule_seconds(parser)
    parser.add_argument("--param", type=_param, action="append", default=[],
                        metavar="NAME=X", help="learner parameter (repeatable)")
    parser.add_argument("--updates", choices=["episode", "online"], default="episode",
                        help="episode: an episode's examples are learned when it ends, last "
                             "first (RRL's, default); online: each step's at once")
    parser.add_argument("--policy", default=None, metavar="FILE",
                        help="start from this saved policy (read as data)")
    parser.add_argument("--traces", type=int, default=3,
                        help="with --out: greedy episodes of each evaluation size kept "
                             "step by step in traces.jsonl and replay/ (relrl replay "
                             "DIR/replay shows the world's states) (3)")
    parser.add_argument("--no-speed", action="store_true",
                        help="skip the step-cost and crossing measurements")
    parser.add_argument("--monitor", nargs="?", const="", default=None, metavar="HOST:PORT",
                        help="serve a live web page of the learning: progress, the curve, "
                             "the learned tree and a greedy episode's last state after each "
                             "evaluation (default 127.0.0.1 and a free port, printed at "
                             "start; off localhost a token is required)")
    add_out_options(parser, default=None,
                    what="output folder: results.json, curve.csv, policy.pl, traces.jsonl")


def run(args: argparse.Namespace) -> int:
    """Check the world and the options, learn, print the curve and the evaluation.

    Stopped (Ctrl-C, SIGTERM, SIGHUP: 130, 143, 129) or ended by an error in the world (2),
    it writes what it learned into ``--out``: the policy saved before the evaluation that
    was running, and results.json, timing.json and curve.csv with every evaluation point
    and test size that finished, marked ``"partial": true``."""
    from relrl.errors import USER_ERRORS, ConfigError, UserError
    from relrl.learners import make_world_learner
    from relrl.outdir import OutDir
    from relrl.worlds import World
    from relrl.worlds.learn import LearnConfig, learn_task

    path = Path(args.world)
    if not path.is_file():
        raise ConfigError(f"{args.world}: no such world file")
    make_world_learner(args.learner, **dict(args.param))          # validate before loading
    with World(path, rule_seconds=args.rule_seconds) as world:
        problems = world.problems()
        if len(problems) == 1:
            raise ConfigError(f"{problems[0]} (relrl check --world {args.world})")
        if problems:
            raise ConfigError("\n".join([*problems, f"{len(problems)} problems in the world "
                                         f"(relrl check --world {args.world})"]))
        task_text = args.task or world.task_names()[0].split("(")[0]
        world.task(task_text)                                     # validate now
        train = ([args.size] if args.size is not None else
                 _sizes(args.sizes, "--sizes") if args.sizes is not None
                 else world.train_sizes)
        if args.size is not None and args.size < 1:
            raise ConfigError(f"--size must be at least 1, not {args.size}")
        test = (_sizes(args.eval_sizes, "--eval-sizes") if args.eval_sizes is not None
                else world.test_sizes)
        world.check_instance(task_text, [*train, *test])
        if args.policy:                        # read it now: a bad one claims no folder
            from relrl.policy import not_a_policy_file

            if (problem := not_a_policy_file(args.policy)) is not None:
                raise ConfigError(f"--policy {args.policy}: {problem}")
            world.attach(world.learner(args.learner, **dict(args.param)), 0, task_text)
            world.load_policy(args.policy)
    if args.size is not None and args.sizes:
        raise ConfigError("give --size or --sizes, not both")
    if args.episodes < 0 or (args.episodes == 0 and not args.policy):
        raise ConfigError(f"--episodes must be at least 1 (0 only with --policy), not "
                          f"{args.episodes}")
    if args.eval_episodes < 1:
        raise ConfigError(f"--eval-episodes must be at least 1, not {args.eval_episodes}")
    if args.seed < 0:
        raise ConfigError(f"--seed must be a whole number >= 0, not {args.seed}")
    if args.traces < 0:
        raise ConfigError(f"--traces must be 0 or more, not {args.traces}")
    block = args.block if args.block is not None else max(1, args.episodes // 10)
    if block < 1:
        raise ConfigError(f"--block must be at least 1, not {block}")
    params = dict(args.param)
    check_restart_options(args)
    config = LearnConfig(world=str(path.resolve()), task=task_text, learner=args.learner,
                         params=params, train_sizes=train, test_sizes=test,
                         episodes=args.episodes, block=block,
                         eval_episodes=args.eval_episodes, seed=args.seed,
                         updates=args.updates, speed=not args.no_speed,
                         rule_seconds=args.rule_seconds, restarts=args.restarts,
                         check_episodes=args.check_episodes)

    def show(event: dict) -> None:
        e = event["entry"]
        if event["kind"] == "check":
            print(check_line(e, args.restarts), flush=True)
            return
        print(f"episodes {e['episodes']:6d}  steps {e['learning_steps']:7d}  of optimal "
              f"{_of(e['optimality'])}  reached {e['success']:.3f}  positions "
              f"{e['memory_positions']}{_unreachable(e)}", flush=True)

    print(f"{args.learner} learns {task_text} on sizes {','.join(map(str, train))} "
          f"({args.episodes} episodes, seed {args.seed}); greedy evaluation of "
          f"{args.eval_episodes} episodes:")
    from relrl.episodes import StopRequest

    stop = StopRequest(force=False)  # each signal stops the running call into Prolog
    try:
        # a stop signal from here on ends the run with what it learned written
        with stop.installed(), _live_monitor(args.monitor, config) as hub:
            if args.out is None:
                result = learn_task(config, report=show, policy_in=args.policy, monitor=hub,
                                    stop=stop)
                _summary(result, result["timing"])
                return _late(stop)
            with OutDir.claim(args.out, command=args.command_line, overwrite=args.overwrite,
                              outputs=OUTPUTS) as out:
                try:
                    result = learn_task(config, report=show, policy_in=args.policy,
                                        policy_out=out.path / "policy.pl",
                                        traces=args.traces, monitor=hub, stop=stop)
                except (KeyboardInterrupt, *USER_ERRORS) as exc:
                    _keep_partial(out, config, exc)
                    raise
                timing = result["timing"]
                files = _write(out.path, config, result)
                out.status = "complete"
    except KeyboardInterrupt as exc:
        exc.signum = stop.signum or 2  # type: ignore[attr-defined]
        raise
    except USER_ERRORS as exc:
        kept = getattr(exc, "kept", None)
        if kept is None:
            raise
        raise UserError(f"{exc}; {kept}") from None
    _summary(result, timing)
    print(f"\nwrote {len(files)} files to {out.path}/: "
          f"{', '.join(str(f.relative_to(out.path)) for f in files)}")
    if (out.path / "replay").is_dir():
        print(f"watch the evaluation episodes: relrl replay {out.path / 'replay'}")
    return _late(stop)


def add_restart_options(parser: argparse.ArgumentParser) -> None:
    """``--restarts`` and ``--check-episodes`` (relrl learn, relrl experiment worlds)."""
    parser.add_argument("--restarts", type=int, default=3, metavar="N",
                        help="check the learned policy on greedy episodes of the training "
                             "sizes; when it wastes a move there, learn again from nothing "
                             "(a stream of its own), up to N times, and keep the first "
                             "optimal attempt, else the first (3; 0: no check)")
    parser.add_argument("--check-episodes", type=int, default=1000, metavar="N",
                        help="greedy episodes of that check (1000, and at most --episodes)")


def check_restart_options(args: argparse.Namespace) -> None:
    """Refuse a negative ``--restarts`` or a ``--check-episodes`` below 1."""
    from relrl.errors import ConfigError

    if args.restarts < 0:
        raise ConfigError(f"--restarts must be 0 or more, not {args.restarts}")
    if args.check_episodes < 1:
        raise ConfigError(f"--check-episodes must be at least 1, not {args.check_episodes}")


def check_line(e: dict, restarts: int) -> str:
    """The line printed for an attempt's check."""
    what = (f"of optimal {_of(e['optimality'])}" if e["optimality"] is not None
            else f"reached {e['success']:.3f}")
    who = f"restart {e['attempt']} (seed {e['seed']})" if e["attempt"] else "the policy"
    then = ("kept" if e["perfect"] else
            f"learning again from nothing: restart {e['attempt'] + 1} of {restarts}"
            if e["restart"] else "no restart left: the first attempt is kept")
    return (f"check of {who}: {e['check_episodes']} greedy episodes of the training sizes, "
            f"{what}; {then}")


def _late(stop: Any) -> int:
    """0, or 128 + N when stop signal N came after the learning, as the outputs were
    written (they are whole: the command says so, and the status tells a script)."""
    if stop.signum is None:
        return 0
    import signal
    import sys

    print(f"{signal.Signals(stop.signum).name} came as the outputs were written: they are "
          "complete", file=sys.stderr)
    return 128 + stop.signum


def _keep_partial(out: Any, config: Any, exc: BaseException) -> None:
    """Write what a stopped or failed run learned (``exc.partial``), marked partial, while
    further signals wait; ``exc.kept`` says what was written. Never raises: the first error
    is the one the user must see."""
    from relrl.outdir import deferred_signals

    partial = getattr(exc, "partial", None)
    if partial is None:
        return
    try:
        with deferred_signals():
            files = _write(out.path, config, dict(partial))
    except BaseException as inner:  # whatever it is, the first error goes on
        exc.kept = f"nothing more could be written to {out.path} ({inner})"  # type: ignore
        return
    learned = partial["policy_episodes"]
    policy = (f"policy.pl (learned from {learned} of {config.episodes} episodes)"
              if learned is not None and (out.path / "policy.pl").is_file()
              else "no policy (none was saved yet)")
    names = ", ".join(str(f.relative_to(out.path)) for f in files if f.name != "policy.pl")
    exc.kept = (f"{len(partial['curve'])} evaluation point"  # type: ignore[attr-defined]
                f"{'s' * (len(partial['curve']) != 1)}, {len(partial['test'])} of "
                f"{len(config.test_sizes)} test sizes and {policy} written to {out.path} "
                f"({names}: partial)")


@contextmanager
def _live_monitor(address: str | None, config: Any) -> Iterator[Any]:
    """The live monitor's hub (its page served from a process of its own) when ``address``
    is not None (``""``: localhost and a free port), else None; closed on the way out."""
    if address is None:
        yield None
        return
    from relrl.monitor import Hub, start_live

    hub = Hub(info={"episode": f"{Path(config.world).name}: {config.task}",
                    "learner": {"name": config.learner}, "seed": config.seed,
                    "necessities": ["of optimal"], "responses": None})
    server = start_live(hub, address or None)
    note = " (token required: not bound to localhost)" if server.token else ""
    print(f"monitor: {server.url}{note}", flush=True)
    try:
        yield hub
        hub.status("finished", "learned and evaluated")
    finally:
        hub.finish()
        server.close()


def _of(value: float | None, spec: str = ".3f") -> str:
    """A figure, or ``-`` when there is none (no episode with a known optimum)."""
    return "-" if value is None else format(value, spec)


def _unreachable(score: dict) -> str:
    """A note of the episodes whose goal a search proved unreachable (no optimum, not
    scored), or nothing."""
    n = score.get("unreachable") or 0
    return f"  ({n} episode{'s' if n != 1 else ''} with an unreachable goal: no optimum)" \
        if n else ""


def _summary(result: dict, t: dict) -> None:
    print("evaluation, no further learning:")
    for size, s in result["test"].items():
        print(f"  size {size:>3}: of optimal {_of(s['optimality'])}, reached "
              f"{s['success']:.3f}, steps {s['steps']:.2f} (optimal "
              f"{_of(s['optimal_steps'], '.2f')}){_unreachable(s)}")
    if t.get("learning_steps_per_second"):
        print(f"learning: {t['learning_steps_per_second']:,.0f} steps/s (a batch of episodes "
              f"per crossing)")
    cost = t.get("step_cost_by_size")
    if cost:
        slope = cost.get("slope")
        print("learning-step cost by size (CPU us/step, ratio to the smallest; sizes' ratio): "
              + ", ".join(f"{s}: {cost['us_per_step'][s]:.0f} ({cost['cost_ratio'][s]:.2f}; "
                          f"{cost['size_ratio'][s]:.2f})" for s in cost["us_per_step"]
                          if cost["us_per_step"][s] is not None)
              + (f"; slope {slope:.2f} (cost ∝ size^k, linear: k = 1)" if slope is not None
                 else "")
              + (f", {cost['fit_slope']:.2f} over sizes {cost['fit_sizes'][0]}-"
                 f"{cost['fit_sizes'][-1]}" if cost.get("fit_slope") is not None else ""))
    greedy = (t.get("greedy_episode_cost_by_size") or {}).get("sizes")
    if greedy:
        print("greedy episode cost by size (CPU ms/episode, us/step): "
              + ", ".join(f"{s}: {g['cpu_ms_per_episode']:.1f} ("
                          + (f"{g['cpu_us_per_step']:.0f}" if g["cpu_us_per_step"] else "-")
                          + ")" for s, g in greedy.items()))


def _write(out: Path, config, result: dict) -> list[Path]:
    import csv
    import io

    from relrl.outdir import write_atomic, write_json_atomic

    traces = result.pop("traces", {})
    graph = result.pop("graph", None)
    timing = result.pop("timing")
    files = [write_json_atomic(out / "results.json",
                               {"command": "learn", "config": config.to_dict(), **result}),
             write_json_atomic(out / "timing.json", timing)]
    buf = io.StringIO()
    w = csv.writer(buf)
    keys = ["point", "episodes", "learning_steps", "optimality", "success", "exactly_optimal",
            "steps", "optimal_steps", "memory_positions"]
    w.writerow(keys)
    for c in result["curve"]:
        w.writerow([c[k] for k in keys])
    files.append(write_atomic(out / "curve.csv", buf.getvalue()))
    if (out / "policy.pl").is_file():            # saved before each evaluation
        files.append(out / "policy.pl")
    if traces:
        from relrl.worlds.replay import write_replay

        lines = [json.dumps({"size": int(size), **ep}) for size, eps in traces.items()
                 for ep in eps]
        files.append(write_atomic(out / "traces.jsonl", "\n".join(lines) + "\n"))
        files += write_replay(out / "replay", traces, learner=config.learner,
                              world=Path(config.world).name, task=config.task,
                              seed=config.seed, graph=graph)
    return files
