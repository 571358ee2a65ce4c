"""``relrl bench``: speed of the gateway, the learners, the simulator and perception."""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
from pathlib import Path

HELP = "measure gateway call cost, learner steps/s, simulator and perception rates"
EXAMPLE = ("relrl bench --json bench.json\n"
           "  relrl bench --prolog-step --profile   # the Prolog side of an ETG step alone")


#: The checkout relrl runs from: its top-level ``bench/`` package (beside ``relrl/`` and
#: ``tests/``) holds the measuring harnesses, which are not part of the installed package.
SOURCE_TREE = Path(__file__).resolve().parents[2]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl bench``."""
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    parser.add_argument("--steps", type=int, default=5000, help="timed steps per learner")
    parser.add_argument("--no-perception", action="store_true",
                        help="skip the perception pipeline benchmark")
    parser.add_argument("--no-faces", action="store_true",
                        help="skip the face-recall figures (needs scikit-image)")
    parser.add_argument("--prolog-step", action="store_true",
                        help="only the Prolog side of a control step: record the bench's seeded "
                             "run and replay it in plain swipl, every decision checked "
                             "(microseconds and inferences per step)")
    parser.add_argument("--learner", default="etg",
                        help="with --prolog-step: a learner of the simulator's domains "
                             "(default etg)")
    parser.add_argument("--profile", action="store_true",
                        help="with --prolog-step: SWI-Prolog's profiler over the replayed steps")
    parser.add_argument("--top", type=int, default=25,
                        help="with --profile: predicates listed (default 25)")


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
    if not args.prolog_step and (args.profile or args.learner != "etg"):
        raise ConfigError("--profile and --learner go with --prolog-step")
    if args.top < 1:
        raise ConfigError(f"--top must be at least 1, not {args.top}")
    path = check_out_file(args.json, "--json") if args.json else None  # before an hour's work
    load_harnesses()
    if args.prolog_step:
        figures = _prolog_step(args)
    else:
        figures = bench_all(steps=args.steps, perception=not args.no_perception,
                            faces=not args.no_faces)
        figures["command"] = args.command_line
        _print(figures)
    if path is not None:
        write_json_atomic(path, figures)
        print(f"wrote {path}")
    json.dumps(figures)  # must be JSON-ready
    return 0


def load_harnesses() -> None:
    """Make the source tree's measuring harnesses importable as the ``bench`` package.

    The harnesses live in ``bench/`` beside ``relrl/`` in a checkout (an editable install
    maps only relrl, perception and head, so the package is loaded from its folder here).

    Raises:
        ConfigError: relrl runs from an installed package without its source tree, or
            another module named ``bench`` is already loaded.
    """
    from relrl.errors import ConfigError

    folder = SOURCE_TREE / "bench"
    init = folder / "__init__.py"
    if not init.is_file():
        raise ConfigError("relrl bench measures with the harnesses of relrl's source tree "
                          "(bench/ beside relrl/), which the installed package does not hold: "
                          "run it from a checkout (git clone, then pip install -e .)")
    loaded = sys.modules.get("bench")
    if loaded is not None:
        if Path(getattr(loaded, "__file__", "") or "").resolve() != init.resolve():
            raise ConfigError(f"relrl bench needs the source tree's {folder}, but another "
                              f"module named bench is loaded ({loaded!r})")
        return
    spec = importlib.util.spec_from_file_location("bench", init,
                                                  submodule_search_locations=[str(folder)])
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench"] = module
    spec.loader.exec_module(module)


def _prolog_step(args: argparse.Namespace) -> dict:
    """``--prolog-step``: the figures of the source tree's bench/stepbench.py, printed (the
    profile as a table)."""
    from relrl.bench import stepbench
    from relrl.learners import make_learner

    make_learner(args.learner)  # an unknown name is a ConfigError before any work
    figures = stepbench().bench_prolog_step(args.learner, steps=args.steps, profile=args.profile,
                                top=args.top)
    profile = figures.pop("profile", None)
    _print(figures)
    if profile is not None:
        print(f"profile ({profile['passes']} passes over the timed steps, "
              f"{profile['ticks']} ticks): cumulative %, self %, calls per step")
        if not profile["predicates"]:
            print("  no samples: the profiler needs longer runs (--steps 1000 or more)")
        for row in profile["predicates"]:
            print(f"  {row['cumulative']:6.1f} {row['self']:6.1f} {row['calls_per_step']:8.2f}"
                  f"  {row['predicate']}")
        figures["profile"] = profile
    return figures
