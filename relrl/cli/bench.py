"""``relrl bench``: speed of the gateway, the learners, the simulator and perception."""

from __future__ import annotations

import argparse
import json

HELP = "measure gateway call cost, learner steps/s, simulator and perception rates"
EXAMPLE = "relrl bench --json bench.json"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl bench``."""
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    parser.add_argument("--steps", type=int, default=5000, help="timed steps per learner")
    parser.add_argument("--no-perception", action="store_true",
                        help="skip the perception pipeline benchmark")
    parser.add_argument("--no-faces", action="store_true",
                        help="skip the face-recall figures (needs scikit-image)")


def _print(d: dict, indent: str = "") -> None:
    for key, value in d.items():
        if isinstance(value, dict):
            print(f"{indent}{key}:")
            _print(value, indent + "  ")
        elif isinstance(value, float):
            print(f"{indent}{key}: {value:,.2f}")
        else:
            print(f"{indent}{key}: {value}")


def run(args: argparse.Namespace) -> int:
    """Run the benchmarks and print them."""
    from relrl.bench import bench_all
    from relrl.errors import ConfigError
    from relrl.outdir import check_out_file, write_json_atomic

    if args.steps < 100:
        raise ConfigError(f"--steps must be at least 100, not {args.steps}")
    path = check_out_file(args.json, "--json") if args.json else None  # before an hour's work
    figures = bench_all(steps=args.steps, perception=not args.no_perception,
                        faces=not args.no_faces)
    _print(figures)
    if path is not None:
        write_json_atomic(path, figures)
        print(f"wrote {path}")
    json.dumps(figures)  # must be JSON-ready
    return 0
