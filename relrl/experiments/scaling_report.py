"""The scaling benchmark end to end: jobs -> summary -> results.json, CSVs, plots.

Files (in the output folder): ``results.json`` (every number and the full configuration;
``"partial": true`` when stopped early), ``timing.json`` (wall clock, steps/s), ``scaling.csv``
(per learner and size), ``curves.csv`` (every evaluation point of every job),
``transfer.csv``, ``speed.csv``, ``memory_vs_size.png`` (log axes), ``time_to_threshold.png``,
``transfer.png``, and ``domains/`` (the generated domain of every world used).
"""

from __future__ import annotations

import platform
from pathlib import Path
from typing import Any

from relrl.experiments.results import (
    pyplot_or_note,
    save_figure,
    skip_plots,
    write_csv,
    write_json_atomic,
)
from relrl.experiments.runner import raise_kept, run_jobs
from relrl.experiments.scaling import ScalingConfig, growth, run_scaling_job, summarize
from relrl.machine import machine_info

__all__ = ["OUTPUTS", "run_scaling", "scaling_table"]


#: the files and folders the scaling benchmark writes (checked for links before it runs).
OUTPUTS = ("results.json", "timing.json", "scaling.csv", "transfer.csv", "curves.csv",
           "speed.csv", "memory_vs_size.png", "time_to_threshold.png", "transfer.png",
           "PLOTS.txt", "domains/", "tensorboard/")

def _label(args: tuple) -> str:
    _, learner, size, seed, kind = args
    return f"{learner} P={size} seed {seed}" + (" transfer" if kind == "transfer" else "")


def run_scaling(config: ScalingConfig, out_dir: str | Path, *, workers: int = 1,
                engine: str = "local", address: str | None = None
                ) -> tuple[dict[str, Any], list[Path]]:
    """Run every job of the scaling benchmark and write the outputs to ``out_dir``.

    Stopped by a signal or a failing job, it writes what finished (``"partial": true``);
    a failing job then raises :class:`~relrl.errors.UserError` naming it."""
    from relrl import __version__

    out = Path(out_dir)
    transfer_sizes = (set(config.transfer_sizes) | {config.transfer_from}
                      if config.transfer == "sizes" else set(config.transfer_sizes)
                      if config.transfer != "none" else set())
    for size in sorted(set(config.sizes) | transfer_sizes):
        config.world_of(size).write_domain(out / "domains")
    tasks = [(config, *job) for job in config.jobs()]
    points = config.budget // config.block + 1
    outcome = run_jobs(run_scaling_job, tasks, workers=workers, engine=engine,
                       address=address, units=points, label=_label)
    jobs, timings = [], []
    for i, task in enumerate(tasks):
        result = outcome.results[i]
        if result is not None:
            timing = result.pop("timing")
            timings.append({"learner": task[1], "size": task[2], "seed": task[3],
                            "kind": task[4], **timing})
            jobs.append(result)
            continue
        curve = [ev["entry"] for ev in outcome.events[i] if ev.get("kind") == "point"]
        if curve:
            reached = next((c["learning_steps"] for c in curve
                            if c["cgi_mean"] >= config.threshold), None)
            jobs.append({"learner": task[1], "size": task[2], "seed": task[3],
                         "kind": task[4], "curve": curve, "steps_to_threshold": reached,
                         "learning_steps": curve[-1]["learning_steps"],
                         "cgi_final": curve[-1]["cgi_mean"],
                         "cgi_literal_final": curve[-1]["cgi_literal_mean"],
                         "memory": {"positions": curve[-1]["memory_positions"]},
                         "states_met": None, "partial": True})
    summary = summarize(jobs, config)
    results = {"experiment": "scaling", "relrl_version": __version__,
               "config": config.to_dict(), "seeds": config.seeds,
               "partial": not outcome.complete, "summary": summary,
               "growth": growth(summary), "jobs": jobs}
    if outcome.interrupted:
        results["interrupted_by"] = outcome.interrupted
    if outcome.error:
        results["error"] = outcome.error
    timing = {"wall_seconds": outcome.seconds, "workers": workers, "engine": engine,
              "python": platform.python_version(), "machine": platform.machine(),
              "machine_info": machine_info(), "jobs": timings}
    files = write_outputs(out, results, timing)
    if outcome.error:
        raise_kept(outcome.error, out)
    return results, files


def write_outputs(out: Path, results: dict[str, Any], timing: dict[str, Any]) -> list[Path]:
    """results.json, timing.json, the CSVs and the plots; returns the files written."""
    files = [out / "results.json", out / "timing.json"]
    write_json_atomic(files[0], results)
    write_json_atomic(files[1], timing)
    summary = results["summary"]
    learners = results["config"]["learners"]

    def table(name: str, header: list[str], rows: list[list[Any]]) -> None:
        files.append(write_csv(out / name, header, [
            ["" if v is None else (f"{v:.6g}" if isinstance(v, float) else v) for v in row]
            for row in rows]))

    keys = ["seeds", "reached", "steps_to_threshold", "steps_to_threshold_max", "cgi_final",
            "cgi_literal_final", "memory_positions", "candidates_per_leaf", "candidates_max",
            "states_met", "learning_steps"]
    table("scaling.csv", ["learner", "size", *keys],
          [[lr, int(size), *(row[k] for k in keys)]
           for lr, rows in _ordered(summary["learn"], learners) for size, row in rows])
    table("transfer.csv", ["learner", "size", "cgi_trained", "cgi_unseen", "unseen"],
          [[lr, int(size), row["cgi_trained"], row["cgi_unseen"],
            " ".join(row["unseen"] or [])]
           for lr, rows in _ordered(summary["transfer"], learners) for size, row in rows])
    table("curves.csv", ["learner", "size", "seed", "kind", "point", "learning_steps",
                         "cgi_mean", "cgi_literal_mean", "memory_positions"],
          [[j["learner"], j["size"], j["seed"], j["kind"], c["point"], c["learning_steps"],
            c["cgi_mean"], c["cgi_literal_mean"], c["memory_positions"]]
           for j in results["jobs"] for c in j["curve"]])
    table("speed.csv", ["learner", "size", "seed", "kind", "learning_steps_per_second",
                        "steps_per_second", "gateway_calls_per_step"],
          [[t["learner"], t["size"], t["seed"], t["kind"], t["learning_steps_per_second"],
            t["steps_per_second"], t["gateway_calls_per_step"]] for t in timing["jobs"]])
    files += tensorboard_runs(out, results)
    files += plot(out, results) if not results.get("partial") else skip_plots(out)
    return files


def tensorboard_runs(out: Path, results: dict[str, Any]) -> list[Path]:
    """Every job's curve as a TensorBoard run, ``tensorboard/LEARNER-pSIZE-seedS`` (with
    ``-transfer`` for a transfer job): CGI and memory by learning time units."""
    from relrl.tensorboard import write_event_file

    return [write_event_file(
        out / "tensorboard" / (f"{j['learner']}-p{j['size']}-seed{j['seed']}"
                               + ("-transfer" if j["kind"] == "transfer" else "")),
        [(c["learning_steps"], {"cgi/mean": c["cgi_mean"],
                                "cgi_literal/mean": c["cgi_literal_mean"],
                                "memory/positions": c["memory_positions"]})
         for c in j["curve"]]) for j in results["jobs"]]


def plot(out: Path, results: dict[str, Any]) -> list[Path]:
    """The three figures as PNG files; a note instead without matplotlib."""
    plt, note = pyplot_or_note(out)
    if plt is None:
        return note
    summary, config = results["summary"], results["config"]
    threshold, budget = config["threshold"], config["budget"]
    files = []

    def save(fig: Any, name: str) -> None:
        fig.tight_layout()
        files.append(save_figure(fig, out / name, dpi=120))

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    sizes_seen: set[int] = set()
    learn = _ordered(summary["learn"], config["learners"])
    for learner, rows in learn:
        pts = [(s, r["memory_positions"]) for s, r in rows if r["memory_positions"]]
        if pts:
            sizes_seen |= {p for p, _ in pts}
            ax.plot(*zip(*pts, strict=True), marker="o", label=learner)
    if sizes_seen:
        lo = min(sizes_seen)
        ref = min(r["memory_positions"] for _, rows in learn for _, r in rows
                  if r["memory_positions"])
        xs = sorted(sizes_seen)
        ax.plot(xs, [ref * x / lo for x in xs], ls=":", color="grey", label="linear in P")
    ax.set_yscale("log")
    _size_axis(ax, sorted(sizes_seen))
    ax.set_xlabel("world size P (toy places)")
    ax.set_ylabel("memory after learning (positions)")
    ax.set_title("Memory against world size")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    save(fig, "memory_vs_size.png")

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for learner, rows in learn:
        hit = [(x, r["steps_to_threshold"]) for x, r in rows
               if r["steps_to_threshold"] is not None]
        line, = ax.plot([x for x, _ in hit], [y for _, y in hit], marker="o", label=learner)
        missed = [x for x, r in rows if r["steps_to_threshold"] is None]
        if missed:
            ax.scatter(missed, [budget] * len(missed), marker="^", facecolors="none",
                       edgecolors=line.get_color(), s=60)
    ax.axhline(budget, ls=":", color="grey", label=f"budget ({budget:,}; ^ = not reached)")
    _size_axis(ax, sorted({x for _, rows in learn for x, _ in rows}))
    ax.set_xlabel("world size P (toy places)")
    ax.set_ylabel(f"learning time units to CGI >= {threshold:g}")
    ax.set_title("Time to learn gaze following (mean over seeds that reached it)")
    ax.grid(alpha=0.3)
    ax.legend()
    save(fig, "time_to_threshold.png")

    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    groups = [(learner, size, row) for learner, rows in
              _ordered(summary["transfer"], config["learners"]) for size, row in rows]
    if groups:
        xs = range(len(groups))
        trained = {"places": "trained places", "kinds": "trained kinds",
                   "sizes": f"P={config.get('transfer_from')}, where it learned"}
        ax.bar([x - 0.2 for x in xs], [g[2]["cgi_trained"] or 0 for g in groups], 0.4,
               label=trained.get(config["transfer"], "trained"))
        ax.bar([x + 0.2 for x in xs], [g[2]["cgi_unseen"] or 0 for g in groups], 0.4,
               label="unseen (zero-shot)")
        ax.set_xticks(list(xs))
        ax.set_xticklabels([f"{lr}\nP={s}" for lr, s, _ in groups], fontsize=8)
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("CGI (no learning)")
    ax.set_title("Zero-shot transfer to other world sizes (no learning)"
                 if config["transfer"] == "sizes" else
                 f"Zero-shot transfer ({config['transfer']} held out)")
    ax.legend()
    ax.grid(alpha=0.3, axis="y")
    save(fig, "transfer.png")
    return files


def _ordered(part: dict[str, dict[str, Any]], learners: list[str]
             ) -> list[tuple[str, list[tuple[int, dict[str, Any]]]]]:
    """A summary part's rows in the configured learner order and by increasing size (JSON
    keeps keys sorted as text: "17" before "5")."""
    order = [lr for lr in learners if lr in part] + sorted(set(part) - set(learners))
    return [(lr, sorted(((int(s), r) for s, r in part[lr].items()), key=lambda x: x[0]))
            for lr in order]


def _size_axis(ax: Any, sizes: list[int]) -> None:
    """A log x axis labelled with the world sizes only."""
    from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator

    ax.set_xscale("log")
    if sizes:
        ax.xaxis.set_major_locator(FixedLocator(sizes))
        ax.set_xticklabels([str(s) for s in sizes])
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_minor_formatter(NullFormatter())


def scaling_table(results: dict[str, Any], timing: dict[str, Any] | None = None) -> str:
    """The learning results as a fixed-width text table."""
    speed: dict[tuple[str, int], list[float]] = {}
    for t in (timing or {}).get("jobs", []):
        if t["kind"] == "learn":
            speed.setdefault((t["learner"], t["size"]), []).append(
                t["learning_steps_per_second"])
    lines = [f"{'learner':<12} {'P':>3} {'reached':>7} {'to 0.9':>8} {'CGI':>6} "
             f"{'literal':>7} {'memory':>8} {'cand/leaf':>9} {'steps/s':>8}"]
    learners = results["config"]["learners"]
    for learner, rows in _ordered(results["summary"]["learn"], learners):
        for size, r in rows:
            to = r["steps_to_threshold"]
            sp = speed.get((learner, int(size)))
            lines.append(
                f"{learner:<12} {size:>3} {r['reached']:>3}/{r['seeds']:<3} "
                f"{'never' if to is None else f'{to:,.0f}':>8} {r['cgi_final']:>6.2f} "
                f"{r['cgi_literal_final']:>7.2f} {r['memory_positions']:>8,.0f} "
                + (f"{r['candidates_per_leaf']:>9.1f} " if r.get("candidates_per_leaf")
                   is not None else f"{'-':>9} ")
                + f"{sum(sp) / len(sp) if sp else float('nan'):>8,.0f}"
                + ("  (partial)" if r["partial"] else ""))
    for learner, rows in _ordered(results["summary"]["transfer"], learners):
        for size, r in rows:
            if "from" in r:         # cross-size transfer
                unseen = ("not loaded" if r["cgi_unseen"] is None else
                          f"{r['cgi_unseen']:.2f} (lowest seed {r['cgi_unseen_min']:.2f})")
                lines.append(f"transfer {learner:<12} P={r['from']} -> P={size:<3} learned at "
                             f"{r['cgi_trained'] or 0:.2f}  here {unseen}")
                continue
            lines.append(f"transfer {learner:<12} P={size:<3} trained {r['cgi_trained'] or 0:.2f}"
                         f"  unseen {r['cgi_unseen'] or 0:.2f}")
    return "\n".join(lines)
