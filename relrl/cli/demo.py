"""``relrl demo``: the main job on the simulator, short (what ``make demo`` runs)."""

from __future__ import annotations

import argparse
import time

HELP = "a short Experiment 1 on the simulator: summary table and plots (what make demo runs)"
EXAMPLE = "relrl demo --out runs/demo"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``relrl demo``."""
    from relrl.experiments.sis import PRESETS
    from relrl.outdir import add_out_options

    add_out_options(parser, default="runs/demo", what="output folder")
    parser.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    parser.add_argument("--preset", default=None, choices=sorted(PRESETS),
                        help="run a named setting instead of relrl's fixed task (as "
                             "relrl experiment sis --preset)")


def run(args: argparse.Namespace) -> int:
    """Run the quick Experiment 1 and say where everything is."""
    from relrl.errors import ConfigError
    from relrl.experiments.results import OUTPUTS, summary_table
    from relrl.experiments.runner import command_signals
    from relrl.experiments.sis import SISConfig, run_sis
    from relrl.outdir import OutDir

    if args.workers < 1:
        raise ConfigError(f"--workers must be at least 1, not {args.workers}")
    config = SISConfig.from_preset(args.preset, points=4, eval_runs=5)
    print(f"relrl demo: Experiment 1 (da Silva & Romero 2012) on the Social Interactive "
          f"Simulator,\n  short version: {len(config.learners)} learners "
          f"({', '.join(config.learners)}) x {config.points + 1} evaluation points x "
          f"{config.eval_runs} runs of {config.eval_steps} time units\n"
          f"  setting: {config.setting()}")
    t0 = time.perf_counter()
    with command_signals(), \
            OutDir.claim(args.out, command=args.command_line, overwrite=args.overwrite,
                         default="runs/demo", outputs=OUTPUTS) as out:
        results, files = run_sis(config, out.path, workers=args.workers)
        out.status = "partial" if results.get("partial") else "complete"
    print()
    print(summary_table(results["summary"]))
    print(f"\n(CGI: correct gaze index, Eq. 5; eye contacts in the first "
          f"{config.opportunities} opportunities; memory in the paper's positions)")
    print(f"done in {time.perf_counter() - t0:.1f} s; results, CSVs and plots in {out.path}/:")
    for f in files:
        print(f"  {f}")
    preset = f" --preset {config.preset}" if config.preset else ""
    print(f"The full experiment: relrl experiment sis{preset} --out runs/exp1")
    return 0
