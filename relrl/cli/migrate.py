"""``relrl migrate DIR``: a session recorded as a folder of frames by earlier relrl, as the
one ``session.mcap`` a recording is now (the old files are kept)."""

from __future__ import annotations

import argparse

HELP = "convert a session recorded as a folder of frames (earlier relrl) to DIR/session.mcap"
EXAMPLE = "relrl migrate runs/watch && relrl replay runs/watch"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl migrate``."""
    parser.add_argument("folder", nargs="+", metavar="DIR",
                        help="session folders with frames.jsonl and frames/ (each gets its "
                             "session.mcap; nothing in them is changed or removed)")


def run(args: argparse.Namespace) -> int:
    """Migrate each folder; a folder that fails is one line, exit 2, after the others."""
    import sys

    from relrl.errors import UserError
    from relrl.recording.migrate import migrate_folder

    failed = 0
    for folder in args.folder:
        try:
            path = migrate_folder(folder)
        except UserError as exc:
            print(f"relrl migrate: {exc}", file=sys.stderr)
            failed += 1
            continue
        print(f"wrote {path} ({path.stat().st_size:,} bytes)")
    return 2 if failed else 0
