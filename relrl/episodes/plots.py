"""Plots of an episode run (matplotlib, optional): rewards over time, the CGI curve of the
evaluations (the paper's Fig. 6) and the Table 1 rates next to the paper's."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["plot_episode"]


def plot_episode(out: Path, summary: dict[str, Any], rewards: list[float]) -> list[Path]:
    """Write ``rewards.png``, ``cgi.png`` (with evaluations) and ``table1.png`` (with naming
    executions) to ``out``; returns the files (none when matplotlib is missing)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    from relrl.experiments.results import save_figure

    files = []
    # on devices, evaluations and naming ran on the scripted world: the titles say so
    sim = " - SIMULATED" if summary.get("where", {}).get("simulated_evaluation") else ""
    if rewards:
        fig, ax = plt.subplots(figsize=(6, 3))
        r = np.asarray(rewards)
        k = min(10, len(r))
        ax.plot(np.arange(1, len(r) + 1), r, lw=0.6, alpha=0.5, label="reward")
        ax.plot(np.arange(k, len(r) + 1), np.convolve(r, np.ones(k) / k, "valid"),
                label=f"mean of {k}")
        ax.set_xlabel("time unit")
        ax.set_ylabel("reward")
        ax.legend(loc="lower right")
        fig.tight_layout()
        files.append(save_figure(fig, out / "rewards.png", dpi=100))
    if summary.get("evaluation"):
        pts = summary["evaluation"]
        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.errorbar([p["units"] for p in pts], [p["cgi_mean"] for p in pts],
                    yerr=[p["cgi_std"] for p in pts], marker="o", capsize=3)
        ax.set_ylim(0, 1.05)
        ax.set_xlabel(f"learning time units ({summary.get('time_unit', 'step')}s)")
        ax.set_ylabel("CGI (mean +- sd of runs)")
        ax.set_title("Learning evolution (cf. the paper's Fig. 6)" + sim)
        fig.tight_layout()
        files.append(save_figure(fig, out / "cgi.png", dpi=100))
    if summary.get("table1") and summary["table1"]["rates"] is not None:
        rates, paper = summary["table1"]["rates"], summary["table1"]["paper"]
        keys = list(paper)
        x = np.arange(len(keys))
        fig, ax = plt.subplots(figsize=(6.5, 3.5))
        ax.bar(x - 0.2, [rates[k][0] for k in keys], 0.4, yerr=[rates[k][1] for k in keys],
               label="measured", capsize=3)
        ax.bar(x + 0.2, [paper[k][0] for k in keys], 0.4, yerr=[paper[k][1] for k in keys],
               label="paper", capsize=3)
        ax.set_xticks(x, [k.replace("_", " ") for k in keys])
        ax.set_ylabel("rate (%)")
        ax.set_title("Declarative pointing (Table 1)" + sim)
        ax.legend()
        fig.tight_layout()
        files.append(save_figure(fig, out / "table1.png", dpi=100))
    return files

