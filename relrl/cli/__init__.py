"""The ``relrl`` command: one entry point, one module per subcommand.

Each subcommand module in :data:`SUBCOMMANDS` provides ``HELP`` (one line), ``EXAMPLE``,
``add_arguments(parser)`` and ``run(args) -> int``. Modules keep heavy imports (OpenCV,
pyserial, matplotlib) inside ``run`` so ``relrl --help`` stays fast and needs no SWI-Prolog
(the learner registry, Prolog's, is asked when a command runs).

Errors a user can cause (:data:`relrl.errors.USER_ERRORS`: relrl's ``UserError`` and the error
bases of the ``head`` and ``perception`` packages) print one line and exit 2 (an error that
lists several problems -- a bad episode script -- prints one ``file:line: problem`` line
each, then the count).
"""

from __future__ import annotations

import argparse
import importlib
import shlex
import sys
from collections.abc import Sequence

__all__ = ["main", "SUBCOMMANDS"]

#: subcommand name -> module (looked up by name, no if-chains).
SUBCOMMANDS: dict[str, str] = {
    "check": "relrl.cli.check",
    "shell": "relrl.cli.shell",
    "bench": "relrl.cli.bench",
    "experiment": "relrl.cli.experiment",
    "run": "relrl.cli.run",
    "perceive": "relrl.cli.perceive",
    "head": "relrl.cli.head",
    "demo": "relrl.cli.demo",
    "examples": "relrl.cli.examples",
    "replay": "relrl.cli.replay",
    "migrate": "relrl.cli.migrate",
    "tree": "relrl.cli.tree",
    "report": "relrl.cli.report",
    "learn": "relrl.cli.learn",
    "evaluate": "relrl.cli.evaluate",
}


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    """Build the full parser with every subcommand that is installed."""
    from relrl import __version__

    parser = _Parser(prog="relrl", description="Relational reinforcement learning for social "
                     "robots: shared attention with knowledge in SWI-Prolog.")
    parser.add_argument("--version", action="version", version=f"relrl {__version__}")
    _add_verbosity(parser, 0)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name, modname in SUBCOMMANDS.items():
        try:
            mod = importlib.import_module(modname)
        except ModuleNotFoundError as exc:
            if exc.name == modname:
                continue  # subcommand not built yet
            raise
        example = getattr(mod, "EXAMPLE", "")
        p = sub.add_parser(name, help=mod.HELP, description=mod.HELP,
                           epilog=f"example:\n  {example}" if example else None,
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        mod.add_arguments(p)
        _add_verbosity(p, argparse.SUPPRESS)  # also after the subcommand (and its own ones)
        p.set_defaults(_run=mod.run)
    return parser


def _add_verbosity(parser: argparse.ArgumentParser, default: object) -> None:
    """``-v``/``-q`` (where a subcommand has not taken the letters for itself), also on the
    subcommands of a subcommand (``relrl experiment sis -q``)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in action.choices.values():
                _add_verbosity(child, argparse.SUPPRESS)
    taken = parser._option_string_actions
    if "-v" not in taken and "--verbose" not in taken:
        parser.add_argument("-v", "--verbose", action="count", default=default,
                            help="more messages (-vv: debug)")
    if "-q" not in taken and "--quiet" not in taken:
        parser.add_argument("-q", "--quiet", action="count", default=default,
                            help="only warnings and errors; no progress bars")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``relrl`` command line; returns the exit status."""
    from relrl import log
    from relrl.errors import USER_ERRORS

    parser = build_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    args = parser.parse_args(argv)
    verbose, quiet = getattr(args, "verbose", 0), getattr(args, "quiet", 0)
    log.setup(min(int(verbose), 2) - min(int(quiet is True or quiet), 1))
    args.command_line = "relrl " + shlex.join(argv)  # for the record of an output folder
    if not getattr(args, "_run", None):
        parser.print_help()
        return 2
    try:
        return int(args._run(args) or 0)
    except USER_ERRORS as exc:
        *problems, last = str(exc).splitlines() or [type(exc).__name__]
        for line in problems:  # several problems: "file:line: problem" each, then a count
            print(line, file=sys.stderr)
        print(f"relrl {args.command}: {last}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        kept = getattr(exc, "kept", None)  # what a run wrote before it stopped
        print(f"relrl {args.command}: interrupted" + (f"; {kept}" if kept else ""),
              file=sys.stderr)
        return 128 + getattr(exc, "signum", 2)  # SIGINT, or the signal that stopped it
    except BrokenPipeError:  # output piped into head & co.
        sys.stderr.close()
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
