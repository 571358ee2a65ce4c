"""``relrl replay DIR``: the monitor's page over a recorded session, with a timeline."""

from __future__ import annotations

import argparse
import math
import time

HELP = "replay a recorded session in the browser: scrub through its time line"
EXAMPLE = ("relrl run examples/episodes/hello.toml --out runs/hello --record && "
           "relrl replay runs/hello")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl replay``."""
    parser.add_argument("folder", help="a session folder written by relrl run --out DIR "
                                       "(--record adds frames and the tree)")
    parser.add_argument("--address", default=None, metavar="HOST:PORT",
                        help="where to serve (default 127.0.0.1 and a free port; off "
                             "localhost a token is required)")
    parser.add_argument("--seconds", type=float, default=None,
                        help="serve this many seconds (a number > 0), then stop (default: "
                             "until Ctrl-C)")


def run(args: argparse.Namespace) -> int:
    """Serve the recording until Ctrl-C (or ``--seconds``)."""
    from relrl.errors import ConfigError
    from relrl.monitor import start_replay
    from relrl.monitor.replay import Recording

    if args.seconds is not None and not (math.isfinite(args.seconds) and args.seconds > 0):
        raise ConfigError(f"--seconds must be a number of seconds > 0, not {args.seconds}")
    rec = Recording(args.folder)  # errors before the server starts
    server = start_replay(rec, args.address)
    try:
        note = " (token required: not bound to localhost)" if server.token else ""
        print(f"replay of {rec.folder} ({len(rec.rows)} time units, {len(rec.frames)} frames): "
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
