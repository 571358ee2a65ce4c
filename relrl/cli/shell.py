"""``relrl shell``: query the knowledge base interactively."""

from __future__ import annotations

import argparse
import sys

HELP = "interactive prompt over the live knowledge base (also reads piped queries)"
EXAMPLE = 'echo "response(R)." | relrl shell examples/domains/fruits.pl'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl shell``."""
    parser.add_argument("domain", nargs="*", metavar="DOMAIN.pl", help="domain files to load")
    parser.add_argument("--policy", metavar="FILE",
                        help="a learned policy (ETG tree, behaviour rules) saved by relrl")
    parser.add_argument("--learner", metavar="NAME",
                        help="start a fresh learner of the simulator's domains (etg, tg, "
                             "...) for :step")
    parser.add_argument("--timeout", type=float, default=10.0, metavar="S",
                        help="seconds each answer may take (default 10; positive: the limit "
                             "cannot be switched off)")
    parser.add_argument("--max", type=int, default=100, metavar="N",
                        help="answers printed per piped query (default 100; at a terminal "
                             "you ask for each answer)")


def run(args: argparse.Namespace) -> int:
    """Run the shell; exit status 2 if a piped query failed with an error."""
    from relrl.errors import ConfigError
    from relrl.kb import KnowledgeBase
    from relrl.shell import Shell, check_timeout

    timeout = check_timeout(args.timeout, "--timeout")
    if args.max < 1:
        raise ConfigError(f"--max {args.max}: use a whole number >= 1")
    kb = KnowledgeBase(*args.domain)
    try:
        shell = Shell(kb, max_solutions=args.max, timeout=timeout)
        from relrl import policy

        if args.policy:
            policy.load_policy(shell, args.policy)
        elif args.learner:
            policy.attach_learner(shell, args.learner)
        if hasattr(sys.stdin, "reconfigure"):  # bytes that are not UTF-8 become U+FFFD
            sys.stdin.reconfigure(errors="replace")
        if sys.stdin.isatty():
            shell.interact()
            return 0
        shell.run_lines(sys.stdin)
        return 2 if shell.errors else 0
    finally:
        kb.close()
