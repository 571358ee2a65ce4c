"""Experiment 1 end to end: jobs -> aggregate -> files."""

from __future__ import annotations

import platform
import time
from pathlib import Path
from typing import Any

from relrl.experiments.report import aggregate, write_outputs
from relrl.experiments.runner import run_jobs
from relrl.experiments.sis import PAPER, SISConfig, merge_parts, run_job

__all__ = ["run_sis"]


def run_sis(config: SISConfig, out_dir: str | Path, *, workers: int = 1
            ) -> tuple[dict[str, Any], list[Path]]:
    """Run every (learner, seed) job of Experiment 1 and write the outputs to ``out_dir``."""
    from relrl import __version__

    out = Path(out_dir)
    t0 = time.perf_counter()
    jobs = config.jobs()
    # Split each job's evaluation runs over the workers so that few jobs still fill them.
    n_parts = max(1, min(workers, config.eval_runs)) if workers > 1 else 1
    bounds = [(config.eval_runs * k // n_parts, config.eval_runs * (k + 1) // n_parts)
              for k in range(n_parts)]
    tasks = [(config, name, seed, None, b) for name, seed in jobs for b in bounds]
    parts = run_jobs(run_job, tasks, workers=workers, units_per_job=config.points + 1)
    raw = [merge_parts([p for p in parts if (p["learner"], p["seed"]) == (name, seed)])
           for name, seed in jobs]
    wall = time.perf_counter() - t0
    timing = {"wall_seconds": wall, "workers": workers, "python": platform.python_version(),
              "machine": platform.machine(),
              "jobs": [{"learner": r["learner"], "seed": r["seed"], **r.pop("timing")}
                       for r in raw]}
    results = {
        "experiment": "sis",
        "relrl_version": __version__,
        "config": config.to_dict(),
        "seeds": config.seeds,
        "summary": aggregate(raw, config.learners),
        "jobs": raw,
        "paper": PAPER,
    }
    files = write_outputs(out, results, timing)
    return results, files
