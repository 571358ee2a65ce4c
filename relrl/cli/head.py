"""``relrl head``: look, report status and calibrate a robotic head (real or simulated)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

__all__ = ["EXAMPLE", "HELP", "add_arguments", "run"]

HELP = "move, inspect and calibrate the robotic head (serial servo controller or simulated)"
EXAMPLE = "relrl head --port /dev/ttyUSB0 --protocol pms5005 look left_down"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``head`` options and its ``look``, ``status`` and ``calibrate`` actions."""
    parser.add_argument("--port", default="sim",
                        help="serial device or pyserial URL (loop://, socket://HOST:PORT), or "
                             "'sim' for the simulated head (default: sim)")
    parser.add_argument("--protocol", default=None,
                        help="servo controller protocol: ssc32, maestro or pms5005 "
                             "(default: the calibration's [head] protocol)")
    parser.add_argument("--calibration", default=None, metavar="FILE",
                        help="calibration TOML (default: examples/heads/wha8030.toml)")
    parser.add_argument("--timeout", type=float, default=0.5,
                        help="seconds to wait for each controller answer (default: 0.5)")
    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)

    def action(name: str, help: str, example: str) -> argparse.ArgumentParser:
        return actions.add_parser(name, help=help, description=help,
                                  epilog=f"example:\n  {example}",
                                  formatter_class=argparse.RawDescriptionHelpFormatter)

    look = action("look", "turn to a direction and wait for the move to end",
                  "relrl head --port /dev/ttyUSB0 look left_down")
    look.add_argument("direction", help="left, left_down, down, right_down, right or centre")
    look.add_argument("--stay", action="store_true",
                      help="leave the head there (default: return to centre on exit)")
    emit = action("emit", "play the motor script of a response",
                  "relrl head emit 'look(right)'        # on the simulated head")
    emit.add_argument("response", help="a response term, e.g. 'look(left)' or name_object")
    status = action("status", "print servo positions, motion and errors",
                    "relrl head --port /dev/ttyUSB0 status --json")
    status.add_argument("--json", action="store_true", help="print one JSON object")
    cal = action("calibrate", "jog each servo from stdin keys and write the calibration file "
                 "(keys: + - [ ] m c x n p w q ?)",
                 "relrl head --port /dev/ttyUSB0 --protocol ssc32 calibrate -o myhead.toml")
    cal.add_argument("--output", "-o", default=None, metavar="FILE",
                     help="file to write (default: the --calibration file, or ./head.toml "
                          "when using the shipped example)")


def _print_status(status: dict, as_json: bool) -> None:
    if as_json:
        print(json.dumps(status, sort_keys=True))
        return
    for key in ("port", "protocol"):
        if key in status:
            print(f"{key}: {status[key]}")
    print(f"looking at: {status['looking_at'] or '-'}   moving: {status['moving']}")
    for name, pos in status["positions"].items():
        print(f"  {name:<12} {pos:8.1f} us   target {status['targets'][name]}")
    print(f"errors: {', '.join(status['errors']) or 'none'}   clamped commands: "
          f"{status['clamped']}")


def run(args: argparse.Namespace) -> int:
    """Open the head, do the action, close it (back to centre unless ``look --stay``)."""
    from head import open_head
    from head.calibration import DEFAULT_CALIBRATION, load_calibration
    from relrl.errors import ConfigError
    from relrl.outdir import check_out_file

    if not 0 < args.timeout <= 60:  # also refuses nan
        raise ConfigError(f"--timeout must be more than 0 and at most 60 seconds, not "
                          f"{args.timeout}")
    cal = load_calibration(args.calibration)
    out = None
    if args.action == "calibrate":
        out = args.output or args.calibration
        if out is None or (not args.output and Path(out).resolve() == DEFAULT_CALIBRATION):
            out = "head.toml"  # never overwrite the shipped example by default
        check_out_file(out, "--output", devices=False)  # before any servo is jogged
    options = {} if args.port in ("sim", "sim://") else {"timeout": args.timeout}
    head = open_head(args.port, args.protocol, cal, **options)
    centre = True
    try:
        if args.action == "look":
            head.look(args.direction)
            done = head.wait()
            print(f"looking at {head.looking_at() or '-'}" + ("" if done else " (still moving)"))
            centre = not args.stay
        elif args.action == "emit":
            head.emit(args.response)
            print(f"played {args.response}; looking at {head.looking_at() or '-'}")
            centre = False
        elif args.action == "status":
            _print_status(head.status(), args.json)
            centre = False
        else:
            from head.calibrate import calibrate

            calibrate(head, sys.stdin, sys.stdout, out)
    except BaseException:
        _quiet_close(head)
        raise
    head.close(centre=centre)
    return 0


def _quiet_close(head) -> None:
    """Release the head after an error without hiding the error."""
    from head.errors import HeadError

    try:
        head.close()
    except HeadError:
        pass
