"""``relrl check DOMAIN.pl [--policy FILE]``: load a domain, validate it and list its
declarations; with ``--policy``, also check a saved policy against it as a whole;
``relrl check --world WORLD.pl``: the same for a world written in Prolog."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from relrl.kb import KnowledgeBase

HELP = "load and validate a domain file; list its stimuli and facts with their codes"
EXAMPLE = ("relrl check examples/domains/fruits.pl\n"
           "  relrl check examples/domains/fruits.pl --policy runs/hello/hello-policy.pl\n"
           "  relrl check --world examples/worlds/blocks.pl")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl check``."""
    parser.add_argument("domain", nargs="*", metavar="DOMAIN.pl",
                        help="domain file(s) to load, in order")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="print only problems, not the declarations")
    parser.add_argument("--policy", action="append", default=[], metavar="FILE",
                        help="also check a saved policy (.pl or .npz) against the domain, as "
                             "a run or the shell would load it (repeatable)")
    from perception.vocabulary import WORLDS

    def world(text: str) -> str:
        if text in WORLDS or text.endswith(".pl"):
            return text
        raise argparse.ArgumentTypeError(
            f"{text!r} is neither a world's percepts ({', '.join(WORLDS)}) nor a world file "
            "(WORLD.pl)")

    parser.add_argument("--world", metavar="NAME|WORLD.pl", type=world,
                        help="a world file written in Prolog (WORLD.pl, docs/worlds.md): "
                             "check it instead of a domain; or a world's percepts, to also "
                             "warn about a domain's facts that can never hold and stimuli "
                             "never perceived (" + "; ".join(
                                 f"{name}: {v.description}" for name, v in WORLDS.items())
                        + ")")
    from relrl.cli.learn import add_rule_seconds

    add_rule_seconds(parser)


def run(args: argparse.Namespace) -> int:
    """Check the domain; exit status 0 when valid, 2 when it has problems (load warnings
    and, with ``--world``, facts the world can never make hold count as problems). Warnings
    about the tg learner's language bias are printed and do not count as problems. With
    ``--world WORLD.pl``, check that world file instead."""
    from perception.vocabulary import WORLDS
    from relrl.errors import ConfigError, PrologLoadError
    from relrl.kb import KnowledgeBase
    from relrl.validate import bias_warnings, describe, validate, world_warnings

    if args.world and args.world not in WORLDS:
        if args.domain or args.policy:
            raise ConfigError("relrl check --world WORLD.pl checks a world file alone; "
                              "give domain files (and --policy) without it")
        return _check_world(args)
    if not args.domain:
        raise ConfigError("give a domain file (relrl check DOMAIN.pl) or a world file "
                          "(relrl check --world WORLD.pl)")
    kb = KnowledgeBase()
    problems: list[str] = []
    try:
        for path in args.domain:
            try:
                for w in kb.load(path, strict=False):
                    problems.append(str(w))
            except PrologLoadError as exc:
                _print_problems(problems + _load_problems(exc))
                return 2
        problems.extend(validate(kb))
        if args.world:
            problems.extend(world_warnings(kb, args.world))
        checked = [] if problems else [_check_policy(kb, p, problems) for p in args.policy]
        if problems:  # the problems alone: a listing of a broken domain would bury them
            _print_problems(problems)
            return 2
        if not args.quiet:
            print(describe(kb))
        for warning in bias_warnings(kb):     # a valid domain, a bias that will not scale
            print(warning, file=sys.stderr)
        if not args.quiet:
            print(f"ok: {', '.join(args.domain)} is valid")
            for line in checked:
                print(line)
        return 0
    finally:
        kb.close()


def _check_policy(kb: KnowledgeBase, path: str, problems: list[str]) -> str:
    """Load the policy at ``path`` into a fresh learner of its kind (every check a load
    makes); a problem is appended to ``problems``. Returns the line that says it is ok."""
    from relrl.errors import UserError
    from relrl.learners import make_learner
    from relrl.loop import Agent
    from relrl.policy import policy_learner

    try:
        name = policy_learner(path, kb)
        agent = Agent(kb, make_learner(name), seed=0)
        agent.learner.load(path)
    except UserError as exc:
        problems.append(str(exc))
        return ""
    positions = agent.learner.size()["positions"]
    return f"ok: {path} is a valid {name} policy for it ({positions} positions)"


def _check_world(args: argparse.Namespace) -> int:
    """Load and validate a world file (prolog/world_check.pl); list what it declares."""
    from pathlib import Path

    from relrl.errors import ConfigError, PrologLoadError
    from relrl.validate import bias_warnings
    from relrl.worlds import World

    path = Path(args.world)
    if not path.is_file():
        raise ConfigError(f"--world {args.world}: no such world file, and not a world's "
                          f"percepts (sis, episodes, fruits)")
    try:
        world = World(path, rule_seconds=args.rule_seconds)
    except PrologLoadError as exc:
        _print_problems(_load_problems(exc))
        return 2
    with world:
        problems, warnings = world.check()
        if not args.quiet:
            print(f"tasks: {', '.join(world.task_names())}")
            print(f"actions: {', '.join(_text(a) for a in world.actions)}")
            print(f"relations (the learner's view): "
                  f"{', '.join(_text(r) for r in world.relations) or '(none declared)'}")
            print(f"sizes: train {world.train_sizes}, test {world.test_sizes or '-'}")
            optimal = ("stated (optimal_steps/3), checked by search" if world.optimal_known
                       else "by breadth-first search")
            print(f"optimal steps: {optimal}")
            if world.discount is not None:
                print(f"discount: {world.discount:g}")
            for learner, params in world.learner_params.items():
                print(f"{learner}'s parameters (learner_param/3): "
                      + ", ".join(f"{k}={v:g}" for k, v in params.items()))
        for warning in [*bias_warnings(world.kb), *warnings]:
            print(warning, file=sys.stderr)
        if problems:
            _print_problems(problems)
            return 2
        if not args.quiet:
            print(f"ok: {args.world} is a valid world")
        return 0


def _text(term) -> str:
    from relrl.worlds.world import _text as text

    return text(term)


def _load_problems(exc) -> list[str]:
    """``file:line: problem`` lines of a file that did not load."""
    return [f"{path}:{line}: {text}" if line else f"{path}: {text}"
            for path, line, text in exc.problems]


def _print_problems(problems: list[str]) -> None:
    for p in problems:
        print(p, file=sys.stderr)
    print(f"{len(problems)} problem{'s' if len(problems) != 1 else ''}", file=sys.stderr)
