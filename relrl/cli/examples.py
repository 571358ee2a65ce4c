"""``relrl examples``: where the shipped examples and the knowledge layer are; copy them."""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["EXAMPLE", "HELP", "add_arguments", "run"]

HELP = "list the example domains, episodes, head calibrations and worlds relrl ships; copy them"
EXAMPLE = "relrl examples --copy . && relrl check examples/domains/fruits.pl"

#: the kinds of shipped example files, by folder.
_KINDS = {"domains": "*.pl", "episodes": "*.toml", "heads": "*.toml", "worlds": "*.pl"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl examples``."""
    parser.add_argument("--copy", metavar="DIR",
                        help="copy the examples into DIR/examples (DIR is made if missing; "
                             "DIR/examples must not exist)")


def run(args: argparse.Namespace) -> int:
    """List the shipped files, or copy them."""
    from relrl.errors import ConfigError
    from relrl.resources import examples_dir, prolog_dir

    source = examples_dir()
    files = [f for kind, pattern in _KINDS.items() for f in sorted((source / kind).glob(pattern))]
    if args.copy is None:
        print(f"examples shipped with relrl ({source}):")
        for f in files:
            print(f"  examples/{f.relative_to(source)}")
        print(f"knowledge layer for plain SWI-Prolog: swipl {prolog_dir() / 'relrl.pl'} DOMAIN.pl")
        print("copy them here with: relrl examples --copy .")
        return 0
    target_dir = Path(args.copy)
    if target_dir.exists() and not target_dir.is_dir():
        raise ConfigError(f"--copy {args.copy}: not a folder")
    target = target_dir / "examples"
    if target.exists():
        raise ConfigError(f"--copy {args.copy}: {target} already exists (choose another folder)")
    from relrl.outdir import write_atomic

    for f in files:
        write_atomic(target / f.relative_to(source), f.read_bytes())
    print(f"copied {len(files)} example files to {target}")
    return 0
