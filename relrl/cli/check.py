"""``relrl check DOMAIN.pl [--policy FILE]``: load a domain, validate it and list its
declarations; with ``--policy``, also check a saved policy against it as a whole."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from relrl.kb import KnowledgeBase

HELP = "load and validate a domain file; list its stimuli and facts with their codes"
EXAMPLE = ("relrl check examples/domains/fruits.pl\n"
           "  relrl check examples/domains/fruits.pl --policy runs/hello/hello-policy.pl")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl check``."""
    parser.add_argument("domain", nargs="+", metavar="DOMAIN.pl",
                        help="domain file(s) to load, in order")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="print only problems, not the declarations")
    parser.add_argument("--policy", action="append", default=[], metavar="FILE",
                        help="also check a saved policy (.pl or .npz) against the domain, as "
                             "a run or the shell would load it (repeatable)")
    from perception.vocabulary import WORLDS

    parser.add_argument("--world", choices=list(WORLDS),
                        help="also warn about facts that can never hold and stimuli never "
                             "perceived with this world's percepts (" + "; ".join(
                                 f"{name}: {v.description}" for name, v in WORLDS.items())
                        + ")")


def run(args: argparse.Namespace) -> int:
    """Check the domain; exit status 0 when valid, 2 when it has problems (load warnings
    and, with ``--world``, facts the world can never make hold count as problems). Warnings
    about the tg learner's language bias are printed and do not count as problems."""
    from relrl.errors import PrologLoadError
    from relrl.kb import KnowledgeBase
    from relrl.validate import bias_warnings, describe, validate, world_warnings

    kb = KnowledgeBase()
    problems: list[str] = []
    try:
        for path in args.domain:
            try:
                for w in kb.load(path, strict=False):
                    problems.append(str(w))
            except PrologLoadError as exc:
                for path_, line, text in exc.problems:
                    where = f"{path_}:{line}" if line else path_
                    problems.append(f"{where}: {text}")
                _print_problems(problems)
                return 2
        problems.extend(validate(kb))
        if args.world:
            problems.extend(world_warnings(kb, args.world))
        if not args.quiet:
            print(describe(kb))
        for warning in bias_warnings(kb):     # a valid domain, a bias that will not scale
            print(warning, file=sys.stderr)
        checked = [] if problems else [_check_policy(kb, p, problems) for p in args.policy]
        if problems:
            _print_problems(problems)
            return 2
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


def _print_problems(problems: list[str]) -> None:
    for p in problems:
        print(p, file=sys.stderr)
    print(f"{len(problems)} problem{'s' if len(problems) != 1 else ''}", file=sys.stderr)
