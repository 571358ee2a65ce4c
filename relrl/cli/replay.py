"""``relrl replay DIR|FILE.mcap``: the monitor's page over a recorded session, with a
timeline."""

from __future__ import annotations

import argparse
import math
import time

HELP = "replay a recorded session in the browser: scrub through its time line"
EXAMPLE = ("relrl run examples/episodes/hello.toml --out runs/hello --record && "
           "relrl replay runs/hello")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl replay``."""
    parser.add_argument("folder", metavar="DIR|FILE.mcap",
                        help="a session folder written by relrl run --out DIR (--record adds "
                             "its session.mcap: frames and the tree), or a session.mcap")
    parser.add_argument("--address", default=None, metavar="HOST:PORT",
                        help="where to serve (default 127.0.0.1 and a free port; off "
                             "localhost a token is required)")
    parser.add_argument("--seconds", type=float, default=None,
                        help="serve this many seconds (a number > 0), then stop (default: "
                             "until Ctrl-C)")


def run(args: argparse.Namespace) -> int:
    """Serve the recording until Ctrl-C (or ``--seconds``)."""
    import sys

    from relrl.errors import ConfigError
    from relrl.monitor import start_replay
    from relrl.recording.reader import open_recording

    if args.seconds is not None and not (math.isfinite(args.seconds) and args.seconds > 0):
        raise ConfigError(f"--seconds must be a number of seconds > 0, not {args.seconds}")
    rec = open_recording(args.folder)  # errors before the server starts
    if getattr(rec, "cut", None):
        print(f"relrl replay: {rec.path}: {rec.cut}", file=sys.stderr, flush=True)
    server = start_replay(rec, args.address)
    try:
        note = " (token required: not bound to localhost)" if server.token else ""
        where = getattr(rec, "path", rec.folder)
        print(f"replay of {where} ({len(rec.rows)} time units, {len(rec.frames)} frames): "
              f"{server.url}{note}", flush=True)
        print("Ctrl-C ends it", flush=True)
        deadline = None if args.seconds is None else time.monotonic() + args.seconds
        try:
            while deadline is None or time.monotonic() < deadline:
                time.sleep(0.2)
        except KeyboardInterrupt:
            pass
    finally:
        server.close()
    return 0
