"""Aggregating, writing and plotting experiment results.

``results.json`` holds every number, the full configuration, the seeds and the package
version; it is byte-identical for the same configuration and seeds. Wall-clock figures go to
``timing.json``.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["OUTPUTS", "aggregate", "cgi_figure", "loglog_slope", "plot", "pyplot_or_note",
           "save_figure", "skip_plots", "summary_table", "tensorboard_runs", "write_csv",
           "write_json_atomic", "write_outputs"]

#: the files Experiment 1 writes into its folder (checked for links before it runs).
OUTPUTS = ("results.json", "timing.json", "fig5_cgi.csv", "fig4_eye_contacts.csv",
           "memory.csv", "cgi_places.csv", "fig5_cgi.png", "fig4_eye_contacts.png",
           "cgi_places.png", "PLOTS.txt", "tensorboard/")


def write_json_atomic(path: Path, data: Any) -> None:
    """Write JSON to ``path`` through a temporary file and a rename (mode 0644; see
    :func:`relrl.outdir.write_json_atomic`)."""
    from relrl.outdir import write_json_atomic as write

    write(path, data)


def write_csv(path: Path, header: list[str], rows: Any) -> Path:
    """Write a CSV file whole (:func:`relrl.outdir.write_atomic`; on a full disk it does not
    take the space held back for the results); returns ``path``."""
    from relrl.outdir import write_atomic

    buf = io.StringIO(newline="")
    w = csv.writer(buf)
    w.writerow(header)
    w.writerows(rows)
    return write_atomic(path, buf.getvalue(), spare=False)


def loglog_slope(xs: Any, ys: Any) -> float | None:
    """The exponent k of ``y ∝ x^k`` fitted by least squares on logarithms over all the
    points (1: linear growth); None with fewer than two points or a value that is not
    positive."""
    pts = [(x, y) for x, y in zip(xs, ys, strict=True) if x and y and x > 0 and y > 0]
    if len({x for x, _ in pts}) < 2:
        return None
    return float(np.polyfit(np.log([x for x, _ in pts]), np.log([y for _, y in pts]), 1)[0])


def save_figure(fig: Any, path: Path, **kwargs: Any) -> Path:
    """Save a matplotlib figure whole (:func:`relrl.outdir.write_atomic`; on a full disk it
    does not take the space held back for the results), in the format its suffix names, and
    close it; ``kwargs`` go to ``savefig`` (``dpi``). Returns ``path``."""
    import matplotlib.pyplot as plt

    from relrl.outdir import write_atomic

    buf = io.BytesIO()
    try:
        fig.savefig(buf, format=Path(path).suffix.lstrip(".") or "png", **kwargs)
    finally:
        plt.close(fig)
    return write_atomic(path, buf.getvalue(), spare=False)


def aggregate(jobs: list[dict[str, Any]], learners: list[str]) -> dict[str, Any]:
    """Per learner: the CGI curves (relrl's and literal) pooled over seeds, eye contacts,
    memory, states met. Jobs stopped part-way contribute the points they finished."""
    out: dict[str, Any] = {}
    for name in learners:
        mine = sorted((j for j in jobs if j["learner"] == name), key=lambda j: j["seed"])
        if not mine:
            continue
        points = max(len(j["curve"]) for j in mine)
        curve = []
        for p in range(points):
            have = [j["curve"][p] for j in mine if len(j["curve"]) > p]
            runs = [v for c in have for v in c["cgi_runs"]]
            literal = [v for c in have for v in c["cgi_literal_runs"]]
            curve.append({"point": p, "learning_steps": have[0]["learning_steps"],
                          "cgi_mean": float(np.mean(runs)), "cgi_std": float(np.std(runs)),
                          "cgi_literal_mean": float(np.mean(literal)),
                          "cgi_literal_std": float(np.std(literal)),
                          "n_runs": len(runs)})
        n_opp = min(len(j["eye_contacts"]["per_opportunity"]) for j in mine)
        flags = np.array([j["eye_contacts"]["per_opportunity"][:n_opp] for j in mine],
                         dtype=float).reshape(len(mine), n_opp)
        cumulative = np.cumsum(flags, axis=1).mean(axis=0) if n_opp else np.zeros(0)
        established = [j["eye_contacts"]["established"] for j in mine]
        memory = {k: float(np.mean([j["memory"][k] for j in mine])) for k in mine[0]["memory"]}
        evaluation = [j["states_met"]["evaluation"] for j in mine
                      if j["states_met"]["evaluation"] is not None]
        firsts = [j["curve"][1]["memory"] for j in mine if len(j["curve"]) > 1]
        memory_first = ({k: float(np.mean([m[k] for m in firsts])) for k in firsts[0]}
                        if firsts else None)
        out[name] = {
            "curve": curve,
            "cgi_after_first_run": curve[1]["cgi_mean"] if points > 1 else None,
            "cgi_final": curve[-1]["cgi_mean"],
            "cgi_literal_after_first_run": curve[1]["cgi_literal_mean"] if points > 1 else None,
            "cgi_literal_final": curve[-1]["cgi_literal_mean"],
            "eye_contacts": {"mean": float(np.mean(established)),
                             "std": float(np.std(established)),
                             "opportunities": n_opp,
                             "cumulative_mean": [float(c) for c in cumulative]},
            "memory": memory,
            "memory_after_first_run": memory_first,
            "states_met": _mean_or_none([j["states_met"]["learning"] for j in mine]),
            "states_met_evaluation": float(np.mean(evaluation)) if evaluation else None,
            "partial": any(j.get("partial", False) for j in mine),
        }
        if "cgi_places" in mine[0]["curve"][0]:
            out[name]["cgi_places"] = _places_curve(mine, points)
    return out


def _mean_or_none(xs: list[float | None]) -> float | None:
    """The mean of the values that are not None (None when there are none)."""
    values = [x for x in xs if x is not None]
    return float(np.mean(values)) if values else None


def _places_curve(jobs: list[dict[str, Any]], points: int) -> dict[str, list[Any]]:
    """Per place group (trained, held_out), the CGI at each point pooled over seeds and runs
    (correct shifts over shifts; None when no shift was made)."""
    out: dict[str, list[Any]] = {}
    for group in jobs[0]["curve"][0]["cgi_places"]:
        values = []
        for p in range(points):
            runs = [r for j in jobs if len(j["curve"]) > p
                    for r in j["curve"][p]["cgi_places"][group]["runs"]]
            shifts = sum(r[1] for r in runs)
            values.append(sum(r[0] for r in runs) / shifts if shifts else None)
        out[group] = values
    return out


def summary_table(summary: dict[str, Any]) -> str:
    """The results as a fixed-width text table."""
    nan = float("nan")
    places = any("cgi_places" in s for s in summary.values())
    head = (f"{'learner':<12} {'CGI run 1':>9} {'CGI final':>9} {'literal':>8} "
            f"{'eye contacts':>13} {'memory':>8} {'states':>7}")
    lines = [head + (f" {'trained':>8} {'held out':>8}" if places else "")]
    for name, s in summary.items():
        ec = s["eye_contacts"]
        first = s["cgi_after_first_run"]
        line = (f"{name:<12} {first if first is not None else nan:>9.3f} "
                f"{s['cgi_final']:>9.3f} {s['cgi_literal_final']:>8.3f} "
                f"{ec['mean']:>7.1f}/{ec['opportunities']:<5d} "
                f"{s['memory']['positions']:>8.0f} "
                + (f"{s['states_met']:>7.0f}" if s["states_met"] is not None else f"{'-':>7}"))
        if places:
            for group in ("trained", "held_out"):
                v = s.get("cgi_places", {}).get(group, [None])[-1]
                line += f" {v:>8.3f}" if v is not None else f" {'-':>8}"
        lines.append(line + ("  (partial)" if s.get("partial") else ""))
    return "\n".join(lines)


def write_outputs(out_dir: Path, results: dict[str, Any], timing: dict[str, Any]) -> list[Path]:
    """Write results.json, timing.json, the figures' CSVs and (with matplotlib) their PNGs.

    Returns the files written.
    """
    written = [out_dir / "results.json", out_dir / "timing.json"]
    write_json_atomic(written[0], results)
    write_json_atomic(written[1], timing)
    summary = results["summary"]
    written.append(write_csv(
        out_dir / "fig5_cgi.csv",
        ["learner", "point", "learning_steps", "cgi_mean", "cgi_std", "cgi_literal_mean",
         "cgi_literal_std", "n_runs"],
        [[name, c["point"], c["learning_steps"], f"{c['cgi_mean']:.6f}", f"{c['cgi_std']:.6f}",
          f"{c['cgi_literal_mean']:.6f}", f"{c['cgi_literal_std']:.6f}", c["n_runs"]]
         for name, s in summary.items() for c in s["curve"]]))
    written.append(write_csv(
        out_dir / "fig4_eye_contacts.csv", ["learner", "opportunity", "cumulative_eye_contacts"],
        [[name, i, f"{c:.4f}"] for name, s in summary.items()
         for i, c in enumerate(s["eye_contacts"]["cumulative_mean"], start=1)]))
    written.append(write_csv(
        out_dir / "memory.csv", ["learner", "positions", "detail", "states_met"],
        [[name, f"{s['memory']['positions']:g}",
          "; ".join(f"{k}={v:g}" for k, v in s["memory"].items() if k != "positions"),
          "" if s["states_met"] is None else f"{s['states_met']:g}"]
         for name, s in summary.items()]))
    if any("cgi_places" in s for s in summary.values()):
        rows = []
        for name, s in summary.items():
            groups = s.get("cgi_places", {})
            for p in range(len(s["curve"])):
                rows.append([name, p] + ["" if groups.get(g, [None] * (p + 1))[p] is None
                                         else f"{groups[g][p]:.6f}"
                                         for g in ("trained", "held_out")])
        written.append(write_csv(out_dir / "cgi_places.csv",
                                 ["learner", "point", "cgi_trained", "cgi_held_out"], rows))
    written += tensorboard_runs(out_dir, results)
    written += plot(out_dir, summary) if not results.get("partial") else skip_plots(out_dir)
    return written


def _curve_scalars(c: dict[str, Any]) -> dict[str, Any]:
    """An evaluation point's scalars for TensorBoard."""
    memory = c.get("memory") or {}
    return {"cgi/mean": c["cgi_mean"], "cgi/std": c.get("cgi_std"),
            "cgi_literal/mean": c["cgi_literal_mean"],
            **{f"memory/{k}": v for k, v in memory.items()}}


def tensorboard_runs(out_dir: Path, results: dict[str, Any]) -> list[Path]:
    """The curves as TensorBoard runs (``tensorboard --logdir OUT/tensorboard``): one per
    learner, pooled over seeds (CGI at each evaluation point by learning time units, the
    cumulative eye contacts by opportunity), and one per job, ``LEARNER-seedS`` (its CGI
    and memory at each point)."""
    from relrl.tensorboard import write_event_file

    base = out_dir / "tensorboard"
    files = []
    for name, s in results["summary"].items():
        points = [(c["learning_steps"], _curve_scalars(c)) for c in s["curve"]]
        points += [(i, {"eye_contacts/cumulative": v}) for i, v in
                   enumerate(s["eye_contacts"]["cumulative_mean"], start=1)]
        files.append(write_event_file(base / name, points))
    for job in results["jobs"]:
        files.append(write_event_file(base / f"{job['learner']}-seed{job['seed']}",
                                      [(c["learning_steps"], _curve_scalars(c))
                                       for c in job["curve"]]))
    return files


def skip_plots(out_dir: Path) -> list[Path]:
    """A note in place of the figures of an interrupted run (drawing them would delay the
    stop by seconds; the numbers are in results.json and the CSVs)."""
    from relrl.outdir import write_atomic

    return [write_atomic(out_dir / "PLOTS.txt",
                         "The run was interrupted, so no figures were drawn (to stop at once); "
                         "every finished point is in results.json and the CSV files.\n",
                         spare=False)]


def pyplot_or_note(out_dir: Path) -> tuple[Any, list[Path]]:
    """``(matplotlib.pyplot, [])`` drawing off-screen, or ``(None, [note])`` with a note in
    ``out_dir`` saying how to get plots when matplotlib is not installed."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        from relrl.outdir import write_atomic

        return None, [write_atomic(out_dir / "PLOTS.txt",
                                   "matplotlib is not installed, so no PNG plots were drawn; "
                                   "the numbers are in the CSV files.\nInstall the extra to "
                                   "get plots:  pip install 'relrl[plots]'\n", spare=False)]
    return plt, []


def _run_label(summary: dict[str, Any]) -> str:
    """The x label of the curves: runs, with the learning time units between two."""
    for s in summary.values():
        curve = s["curve"]
        if len(curve) > 1:
            block = curve[1]["learning_steps"] - curve[0]["learning_steps"]
            return f"run (evaluation point; {block:,} learning time units each)"
    return "run (evaluation point)"


def _below(ax: Any, columns: int = 2, handles: list[Any] | None = None) -> None:
    """The legend under the axes, where it covers no curve (``handles`` in that order,
    filled column by column); whole-number runs on x."""
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.legend(**({"handles": handles} if handles else {}), loc="upper center",
              bbox_to_anchor=(0.5, -0.16), ncol=columns, fontsize=8, frameon=False)


def cgi_figure(plt: Any, summary: dict[str, Any]) -> tuple[Any, Any]:
    """Fig. 5: each learner's CGI (mean ± s.d.) at each evaluation point, and Eq. 5 taken
    literally (dashed); the legend below the axes, runs as whole numbers."""
    fig, ax = plt.subplots(figsize=(7, 4.8))
    handles = []  # a learner's curve, then its literal one: one column each
    for name, s in summary.items():
        steps = [c["point"] for c in s["curve"]]
        bars = ax.errorbar(steps, [c["cgi_mean"] for c in s["curve"]],
                           yerr=[c["cgi_std"] for c in s["curve"]], marker="o", ms=3,
                           capsize=3, label=name)
        handles += [bars, *ax.plot(steps, [c["cgi_literal_mean"] for c in s["curve"]],
                                   ls="--", lw=1, color=bars[0].get_color(),
                                   label=f"{name} (Eq. 5 literally)")]
    ax.set_ylim(-0.05, 1.05)
    ax.set_xlabel(_run_label(summary))
    ax.set_ylabel("CGI (mean ± s.d.)")
    ax.set_title("Fig. 5 — learning evolution (Social Interactive Simulator)")
    ax.grid(alpha=0.3)
    _below(ax, columns=max(1, min(4, len(summary))), handles=handles)
    return fig, ax


def plot(out_dir: Path, summary: dict[str, Any]) -> list[Path]:
    """Fig. 4 and Fig. 5 as PNG files (and, with held-out places, the CGI on trained and
    held-out places); nothing (and a note) without matplotlib."""
    plt, note = pyplot_or_note(out_dir)
    if plt is None:
        return note

    def save(fig: Any, name: str) -> Path:
        return save_figure(fig, out_dir / name, dpi=120, bbox_inches="tight")

    files = [save(cgi_figure(plt, summary)[0], "fig5_cgi.png")]
    fig, ax = plt.subplots(figsize=(7, 4.8))
    for name, s in summary.items():
        cum = s["eye_contacts"]["cumulative_mean"]
        ax.plot(range(1, len(cum) + 1), cum,
                label=f"{name} ({s['eye_contacts']['mean']:.0f} ± "
                      f"{s['eye_contacts']['std']:.0f})")
    ax.set_xlabel("eye-contact opportunity")
    ax.set_ylabel("eye contacts established (cumulative)")
    ax.set_title("Fig. 4 — capacity of attention (first opportunities)")
    ax.grid(alpha=0.3)
    _below(ax, columns=min(4, max(1, len(summary))))
    files.append(save(fig, "fig4_eye_contacts.png"))
    if any("cgi_places" in s for s in summary.values()):
        fig, ax = plt.subplots(figsize=(7, 4.8))
        for i, (name, s) in enumerate(summary.items()):
            groups = s.get("cgi_places", {})
            for group, style in (("trained", "-"), ("held_out", "--")):
                values = groups.get(group, [])
                points = [p for p, v in enumerate(values) if v is not None]
                ax.plot(points, [values[p] for p in points], style, marker="o", ms=3,
                        color=f"C{i}", label=f"{name}, {group.replace('_', '-')} places")
        ax.set_ylim(-0.05, 1.05)
        ax.set_xlabel(_run_label(summary))
        ax.set_ylabel("CGI (pooled shifts)")
        ax.set_title("Gaze following on trained and held-out places")
        ax.grid(alpha=0.3)
        _below(ax, columns=min(4, 2 * max(1, len(summary))))
        files.append(save(fig, "cgi_places.png"))
    return files
