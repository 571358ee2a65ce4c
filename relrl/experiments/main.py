"""Experiment 1 end to end: jobs -> aggregate -> files (whole, or partial when stopped)."""

from __future__ import annotations

import platform
from pathlib import Path
from typing import Any

from relrl.experiments.report import aggregate, write_outputs
from relrl.experiments.runner import raise_kept, run_jobs
from relrl.experiments.sis import PAPER, SISConfig, job_from_curve, paper_claims, run_job
from relrl.machine import machine_info

__all__ = ["run_sis"]


def _label(args: tuple) -> str:
    return f"{args[1]} seed {args[2]}"


def run_sis(config: SISConfig, out_dir: str | Path, *, workers: int = 1,
            engine: str = "local", address: str | None = None
            ) -> tuple[dict[str, Any], list[Path]]:
    """Run every (learner, seed) job of Experiment 1 and write the outputs to ``out_dir``.

    Stopped by Ctrl-C or SIGTERM, it writes what finished: every evaluation point that all
    parts of a job completed, with ``"partial": true`` in results.json. A job that fails
    stops the run the same way, and then :class:`~relrl.errors.UserError` names the failure.
    """
    from relrl import __version__

    out = Path(out_dir)
    jobs = config.jobs()
    # Split each job's evaluation runs over the workers so that few jobs still fill them.
    n_parts = max(1, min(workers, config.eval_runs)) if workers > 1 else 1
    bounds = [(config.eval_runs * k // n_parts, config.eval_runs * (k + 1) // n_parts)
              for k in range(n_parts)]
    tasks = [(config, name, seed, b) for name, seed in jobs for b in bounds]
    outcome = run_jobs(run_job, tasks, workers=workers, engine=engine, address=address,
                       units=config.points + 1, label=_label)
    raw, timings = [], []
    for name, seed in jobs:
        mine = [i for i, t in enumerate(tasks) if (t[1], t[2]) == (name, seed)]
        done = [outcome.results[i] for i in mine]
        if all(r is not None for r in done):
            curves = [r["curve"] for r in done]
            eval_states = set().union(*(r["eval_states"] for r in done))
            job = job_from_curve(name, seed, curves, done[0]["params"], eval_states)
            timings.append({"learner": name, "seed": seed, "parts": len(done),
                            "seconds": sum(r["timing"]["seconds"] for r in done),
                            "steps": sum(r["timing"]["steps"] for r in done),
                            "gateway_calls_per_step": max(
                                r["timing"]["gateway_calls_per_step"] for r in done)})
        else:
            curves = [[ev["entry"] for ev in outcome.events[i] if ev.get("kind") == "point"]
                      for i in mine]
            job = job_from_curve(name, seed, curves)
            if job is not None:
                job["partial"] = True
        if job is not None:
            raw.append(job)
    for t in timings:
        t["steps_per_second"] = t["steps"] / t["seconds"] if t["seconds"] else 0.0
    timing = {"wall_seconds": outcome.seconds, "workers": workers, "engine": engine,
              "python": platform.python_version(), "machine": platform.machine(),
              "machine_info": machine_info(), "jobs": timings}
    results = {
        "experiment": "sis",
        "relrl_version": __version__,
        "config": config.to_dict(),
        "seeds": config.seeds,
        "partial": not outcome.complete,
        "summary": aggregate(raw, config.learners),
        "jobs": raw,
        "paper": PAPER,
    }
    results["claims"] = paper_claims(results["summary"])
    if outcome.interrupted:
        results["interrupted_by"] = outcome.interrupted
    if outcome.error:
        results["error"] = outcome.error
    files = write_outputs(out, results, timing)
    if outcome.error:
        raise_kept(outcome.error, out)
    return results, files
