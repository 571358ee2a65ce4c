"""Experiment 2 over seeds, learners and both readings of the time unit: Fig. 6 and Table 1.

One job runs ``examples/episodes/experiment2.toml`` (or another script) for one learner, one
time unit and one seed -- learning with evaluations, then the naming executions -- exactly as
``relrl run`` does. The jobs run over worker processes (one Prolog engine each) and the results
go to ``OUT``:

* ``fig6.csv`` -- CGI per evaluation point, per learner, time unit and seed (mean and sd of
  the evaluation runs); ``fig6_summary.csv`` -- mean and sd over the seeds;
* ``table1.csv`` -- the outcome counts of every naming execution; ``table1_summary.csv`` --
  the rates (mean and sd over the executions) per seed and over all executions;
* ``confusion.csv`` -- per learner, time unit, fruit shown and name said, the count;
* ``fig6.png`` and ``table1.png``; ``results.json`` with everything, the configuration and the
  command; ``timing.json`` with the wall clock (kept apart: the rest is the same for the same
  seeds).

Usage::

    python -m relrl.experiments.exp2 --seeds 0-4 --out docs/results/exp2

Learners come from the registry (:func:`relrl.learners.learners`, asked of relrl's Prolog):
every learner of the domains by default, so one that lands later is measured too.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from relrl.experiments.exp2.measures import OUTCOMES, PAPER, merge_confusions, rates
from relrl.machine import machine_info

__all__ = ["main", "run_job", "summarise"]

ROOT = Path(__file__).resolve().parents[3]
DEFAULT_SCRIPT = ROOT / "examples" / "episodes" / "experiment2.toml"


#: the files the sweep writes into its folder (checked for links before it runs).
OUTPUTS = ("fig6.csv", "fig6_summary.csv", "table1.csv", "table1_summary.csv",
           "confusion.csv", "fig6.png", "table1.png", "results.json", "timing.json")

def run_job(script: str, learner: str, seed: int, time_unit: str,
            overrides: dict[str, Any], *, report: Any = None) -> dict[str, Any]:
    """Run the script for one learner, time unit and seed; the parts of its summary the
    sweep needs (``report`` gets one ``point`` event at the end: the progress bar)."""
    from relrl.episodes import RunOptions, load_episode, run_episode
    from relrl.learners import make_learner

    ep = load_episode(script)
    accepted = set(make_learner(learner).params)
    ep.learner, ep.seed, ep.time_unit = learner, int(seed), time_unit
    ep.learner_params = {k: v for k, v in ep.learner_params.items() if k in accepted}
    if ep.evaluation is not None and overrides.get("every"):
        ep.evaluation["every"] = int(overrides["every"])
    if overrides.get("perception"):
        ep.perception = overrides["perception"]
    if overrides.get("executions") is not None and ep.naming is not None:
        ep.naming["executions"] = int(overrides["executions"])
    if time_unit not in overrides.get("table1_units", (time_unit,)):
        ep.naming = None
    t0 = time.perf_counter()
    s = run_episode(ep, RunOptions(plots=False, timeout=float(overrides.get("timeout", 60.0))))
    if report is not None:
        report({"kind": "point", "learner": learner, "seed": int(seed), "point": "done"})
    return {"learner": learner, "time_unit": time_unit, "seed": int(seed),
            "params": s["learner"]["params"],
            "evaluation": s.get("evaluation", []), "table1": s.get("table1"),
            "learning": {"cgi": s["cgi"], "shifts": s["shifts"], "units": s["units"],
                         "control_steps": s["steps"], "memory": s["memory"]},
            "seconds": time.perf_counter() - t0}


def summarise(jobs: list[dict[str, Any]]) -> dict[str, Any]:
    """Fig. 6 over seeds and Table 1 over executions, per learner and time unit."""
    out: dict[str, Any] = {}
    for learner, unit in sorted({(j["learner"], j["time_unit"]) for j in jobs}):
        mine = sorted((j for j in jobs if (j["learner"], j["time_unit"]) == (learner, unit)),
                      key=lambda j: j["seed"])
        curve = []
        for u in sorted({p["units"] for j in mine for p in j["evaluation"]}):
            vals = [p["cgi_mean"] for j in mine for p in j["evaluation"] if p["units"] == u]
            curve.append({"units": u, "cgi_mean": float(np.mean(vals)),
                          "cgi_sd_over_seeds": float(np.std(vals)), "seeds": len(vals),
                          "cgi_per_seed": vals})
        t1 = [j["table1"] for j in mine if j["table1"]]
        executions = [e for t in t1 for e in t["executions"]]
        out[f"{learner}/{unit}"] = {
            "learner": learner, "time_unit": unit, "seeds": [j["seed"] for j in mine],
            "fig6": curve,
            "table1": {"all_executions": rates(executions), "executions": len(executions),
                       "without_presentation": sum(1 for e in executions
                                                   if not e["presentations"]),
                       "per_seed": {str(j["seed"]): rates(j["table1"]["executions"])
                                    for j in mine if j["table1"]}},
            "confusion": merge_confusions([t.get("confusion", {}) for t in t1]),
        }
    return out


def write_outputs(out: Path, results: dict[str, Any], timing: dict[str, Any]) -> list[Path]:
    """CSV tables, plots, ``results.json`` and ``timing.json``."""
    from relrl.experiments.results import write_csv, write_json_atomic

    jobs, summary = results["jobs"], results["summary"]
    files = [out / n for n in ("fig6.csv", "fig6_summary.csv", "table1.csv",
                               "table1_summary.csv", "confusion.csv")]
    write_csv(files[0], ["learner", "time_unit", "seed", "units", "cgi_mean", "cgi_sd_runs",
                          "no_shift_runs"],
               [[j["learner"], j["time_unit"], j["seed"], p["units"], round(p["cgi_mean"], 4),
                 round(p["cgi_std"], 4), p.get("no_shift_runs", 0)]
                for j in jobs for p in j["evaluation"]])
    write_csv(files[1], ["learner", "time_unit", "units", "cgi_mean_over_seeds",
                          "cgi_sd_over_seeds", "seeds"],
               [[s["learner"], s["time_unit"], p["units"], round(p["cgi_mean"], 4),
                 round(p["cgi_sd_over_seeds"], 4), p["seeds"]]
                for s in summary.values() for p in s["fig6"]])
    write_csv(files[2], ["learner", "time_unit", "seed", "execution", "presentations",
                          "missed", "control_steps", "categories", *OUTCOMES],
               [[j["learner"], j["time_unit"], j["seed"], k, e["presentations"], e["missed"],
                 e["steps"], e["categories"], *(e["counts"][o] for o in OUTCOMES)]
                for j in jobs if j["table1"]
                for k, e in enumerate(j["table1"]["executions"])])
    rows = []
    for s in summary.values():
        t1 = s["table1"]
        for seed, r in [*t1["per_seed"].items(), ("all", t1["all_executions"])]:
            rows.append([s["learner"], s["time_unit"], seed]
                        + ([f"{r[o][0]:.2f} +- {r[o][1]:.2f}" for o in OUTCOMES] if r else
                           [("no presentation" if t1["executions"] else "not run")]
                           * len(OUTCOMES)))
    write_csv(files[3], ["learner", "time_unit", "seed", *OUTCOMES], rows)
    write_csv(files[4], ["learner", "time_unit", "shown", "said", "count", "percent_of_shown"],
               [[s["learner"], s["time_unit"], shown, said, n,
                 round(100.0 * n / sum(row.values()), 2)]
                for s in summary.values() for shown, row in s["confusion"].items()
                for said, n in row.items()])
    files += _plots(out, summary)
    write_json_atomic(out / "results.json", results)
    write_json_atomic(out / "timing.json", timing)
    return files + [out / "results.json", out / "timing.json"]


def _plots(out: Path, summary: dict[str, Any]) -> list[Path]:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    from relrl.experiments.results import save_figure

    units = sorted({s["time_unit"] for s in summary.values()})
    fig, axes = plt.subplots(1, len(units), figsize=(5.5 * len(units), 3.8), squeeze=False)
    for ax, unit in zip(axes[0], units, strict=True):
        for s in summary.values():
            if s["time_unit"] == unit:
                ax.errorbar([p["units"] for p in s["fig6"]], [p["cgi_mean"] for p in s["fig6"]],
                            yerr=[p["cgi_sd_over_seeds"] for p in s["fig6"]], marker="o", ms=3,
                            capsize=2, label=s["learner"])
        ax.axvspan(0, 30, color="0.92", zorder=0)
        ax.text(15, 1.02, "no objects", ha="center", fontsize=8)
        ax.set_ylim(0, 1.08)
        ax.set_xlabel(f"learning time units ({unit}s)")
        ax.set_ylabel("CGI (mean over seeds; bars: sd)")
        ax.set_title(f"Fig. 6, time unit = {unit}")
        ax.legend(loc="lower right", fontsize=8)
    fig.text(0.5, 0.005, "paper (text only): a fast rise until the second evaluation, then a "
             "slow rise to a plateau; no values are given", ha="center", fontsize=8)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    files = [save_figure(fig, out / "fig6.png", dpi=100)]

    keys = [k for k, s in summary.items() if s["table1"]["all_executions"]]
    if keys:
        fig, ax = plt.subplots(figsize=(8, 3.6))
        width = 0.8 / (len(keys) + 1)
        x = np.arange(len(OUTCOMES))
        paper = PAPER["table1"]
        ax.bar(x - 0.4 + width / 2, [paper[o][0] for o in OUTCOMES], width,
               yerr=[paper[o][1] for o in OUTCOMES], capsize=2, label="paper", color="0.6")
        for i, k in enumerate(keys):
            r = summary[k]["table1"]["all_executions"]
            ax.bar(x - 0.4 + width * (i + 1.5), [r[o][0] for o in OUTCOMES], width,
                   yerr=[r[o][1] for o in OUTCOMES], capsize=2, label=k)
        ax.set_xticks(x, [o.replace("_", " ") for o in OUTCOMES])
        ax.set_ylabel("rate (%; bars: sd over executions)")
        ax.set_title("Table 1: declarative pointing")
        ax.legend(fontsize=7)
        fig.tight_layout()
        files.append(save_figure(fig, out / "table1.png", dpi=100))
    return files



def _seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        part = part.strip()
        if "-" in part[1:]:
            lo, hi = part.split("-", 1)
            out += list(range(int(lo), int(hi) + 1))
        elif part:
            out.append(int(part))
    return out


def _options(argv: list[str] | None) -> argparse.Namespace:
    from relrl.episodes.script import TIME_UNITS

    parser = argparse.ArgumentParser(prog="python -m relrl.experiments.exp2",
                                     description="Experiment 2 over seeds, learners and both "
                                                 "readings of the time unit")
    parser.add_argument("--script", default=str(DEFAULT_SCRIPT), help="episode script")
    parser.add_argument("--learners", default="all",
                        help="comma-separated learners, or all registered (default)")
    parser.add_argument("--time-units", default=",".join(TIME_UNITS),
                        help="comma-separated readings of the time unit (default: both)")
    parser.add_argument("--seeds", default="0-4", help="seeds, e.g. 0-4 or 0,2 (default 0-4)")
    parser.add_argument("--every", type=int, default=10,
                        help="evaluate every N learning time units (default 10)")
    parser.add_argument("--executions", type=int, default=None,
                        help="naming executions per run (default: the script's)")
    parser.add_argument("--table1-units", default="interaction",
                        help="the time units whose runs also do the naming executions "
                             "(Table 1; default interaction, the documented reading; all: "
                             "every one)")
    parser.add_argument("--perception", choices=["render", "symbolic"], default=None,
                        help="override the script's perception (symbolic: no Table 1)")
    parser.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    parser.add_argument("--timeout", type=float, default=60.0, metavar="SECONDS",
                        help="seconds one control step may run before the job stops, naming "
                             "the rule (default 60: a loaded machine; the robot's own is 10)")
    from relrl.outdir import add_out_options

    add_out_options(parser, default="runs/exp2-sweep",
                    what="output folder: results.json, CSVs, figures")
    return parser.parse_args(argv)


def _check(args: argparse.Namespace) -> tuple[list[str], list[str], list[int]]:
    from relrl.episodes import load_episode
    from relrl.episodes.script import TIME_UNITS
    from relrl.errors import UserError
    from relrl.learners import DOMAINS
    from relrl.learners import learners as registered

    known = registered(DOMAINS)
    learners = (list(known) if args.learners == "all" else
                [x.strip() for x in args.learners.split(",") if x.strip()])
    for name in learners:
        if name not in known:
            raise UserError(f"unknown learner {name!r} (known: {', '.join(known)})")
    units = [x.strip() for x in args.time_units.split(",") if x.strip()]
    for u in units:
        if u not in TIME_UNITS:
            raise UserError(f"unknown time unit {u!r} (use {', '.join(TIME_UNITS)})")
    try:
        seeds = _seeds(args.seeds)
    except ValueError:
        raise UserError(f"--seeds {args.seeds!r}: use e.g. 0-4 or 0,2,3") from None
    if not seeds or not learners or not units:
        raise UserError("give at least one seed, learner and time unit")
    if args.every < 1 or args.workers < 1:
        raise UserError("--every and --workers must be at least 1")
    from relrl.shell import check_timeout

    check_timeout(args.timeout, "--timeout")
    load_episode(args.script)  # check it here, not in a worker
    return learners, units, seeds


def main(argv: list[str] | None = None) -> int:
    """Run the sweep and write the outputs; exit status 2 for a bad option, script or output
    folder (relrl's output policy: refused when it holds files, unless --overwrite; locked
    while the sweep runs)."""
    from relrl.errors import UserError
    from relrl.experiments.runner import command_signals
    from relrl.outdir import OutDir

    args = _options(argv)
    command = " ".join(["python -m relrl.experiments.exp2",
                        *(argv if argv is not None else sys.argv[1:])])
    try:
        learners, units, seeds = _check(args)
        with command_signals(), \
                OutDir.claim(args.out, command=command, overwrite=args.overwrite,
                             default="runs/exp2-sweep", outputs=OUTPUTS) as out:
            code = _sweep(args, out.path, command, learners, units, seeds)
            out.status = "complete" if code == 0 else "partial"
    except UserError as exc:
        print(f"exp2: {exc}", file=sys.stderr)
        return 2
    return code


def _sweep(args: argparse.Namespace, out: Path, command: str, learners: list[str],
           units: list[str], seeds: list[int]) -> int:
    from relrl.experiments.runner import run_jobs

    table1_units = units if args.table1_units == "all" else \
        [u.strip() for u in args.table1_units.split(",") if u.strip()]
    overrides = {"every": args.every, "perception": args.perception,
                 "executions": args.executions, "table1_units": table1_units,
                 "timeout": args.timeout}
    tasks = [(args.script, name, seed, unit, overrides)
             for name in learners for unit in units for seed in seeds]
    outcome = run_jobs(run_job, tasks, workers=args.workers, units=1,
                       label=lambda t: f"{t[1]}/{t[3]} seed {t[2]}")
    jobs = [j for j in outcome.results if j is not None]
    if not outcome.complete:  # a signal or a failing job: the finished jobs are kept
        why = outcome.error or f"stopped by {outcome.interrupted}"
        if not jobs:
            print(f"exp2: {why}; no job finished, nothing written", file=sys.stderr)
            return 2 if outcome.error else _stopped(outcome.interrupted)
    wall = outcome.seconds
    timing = {"wall_seconds": wall, "workers": args.workers,
              "python": platform.python_version(), "machine_info": machine_info(),
              "jobs": [{"learner": j["learner"], "time_unit": j["time_unit"], "seed": j["seed"],
                        "seconds": j.pop("seconds")} for j in jobs]}
    script = Path(args.script).resolve()
    results = {"experiment": "exp2", "command": command,
               "script": str(script.relative_to(ROOT)) if script.is_relative_to(ROOT)
               else str(script),
               "learners": learners, "time_units": units, "seeds": seeds,
               "overrides": overrides, "summary": summarise(jobs), "jobs": jobs,
               "partial": not outcome.complete, "paper": PAPER}
    files = write_outputs(out, results, timing)
    for key, s in results["summary"].items():
        line = f"{key:28s}"
        if s["fig6"]:
            last = s["fig6"][-1]
            line += (f" CGI at {last['units']}: {last['cgi_mean']:.3f} +- "
                     f"{last['cgi_sd_over_seeds']:.3f} over seeds")
        t1 = s["table1"]["all_executions"]
        line += (f"; success {t1['success'][0]:.2f} +- {t1['success'][1]:.2f} %" if t1 else
                 "; Table 1: no presentation" if s["table1"]["executions"] else
                 "; Table 1 not run for this time unit (--table1-units)")
        print(line)
    print(f"wrote {len(files)} files to {out}/ in {wall:.0f} s")
    if not outcome.complete:
        print(f"exp2: {why}; the {len(jobs)} finished jobs of {len(tasks)} are written "
              "(results.json marked partial)", file=sys.stderr)
        return 2 if outcome.error else _stopped(outcome.interrupted)
    return 0


def _stopped(name: str | None) -> int:
    """128 + the number of the signal that stopped the sweep (SIGINT when unknown)."""
    import signal

    return 128 + (signal.Signals[name].value if name in signal.Signals.__members__
                  else signal.SIGINT)

