"""Results tables generated from the runs that produced them, never pasted.

A run folder (what ``relrl experiment ...`` writes) holds ``results.json`` (every number and
the configuration), ``timing.json`` (the machine and wall clock) and ``.relrl-run.json`` (the
command and when it ran). :func:`render` turns a run into Markdown: a provenance line and the
tables of one *view* (``summary``, ``short``, ...) of that experiment.

In a Markdown file, a generated table sits between two comments naming its source::

    <!-- relrl-report results/exp1 summary -->
    ...
    <!-- /relrl-report -->

The path is relative to the Markdown file's folder and stays inside the document's tree (the
git work tree holding it, else its folder, or ``--root DIR``): a marker is text anyone may
write, and it never makes relrl read a file elsewhere. Everything a run's records hold is
rendered as the text it is (:mod:`relrl.markdown`), never as markup, and a results.json is
checked against what its views read before any is rendered (:mod:`relrl.report_schema`).
:func:`update_file` re-renders every such
block in place (``relrl report --update README.md``); :func:`stale_blocks` lists the blocks
that no longer match their source (``relrl report --check``; the test suite runs it on the
shipped docs). Views are looked up in :data:`VIEWS` by (experiment, view); adding an
experiment's tables touches its own renderer only.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from relrl.errors import UserError
from relrl.markdown import Markdown, code, link, text
from relrl.report_schema import check_run

__all__ = ["MULTI_VIEWS", "Run", "VIEWS", "load_run", "render", "render_many",
           "render_report", "stale_blocks", "tree_of", "update_file", "view"]

BLOCK = re.compile(r"<!-- relrl-report (?P<path>\S+) (?P<view>[\w-]+) -->\n"
                   r"(?P<body>.*?)<!-- /relrl-report -->", re.S)


@dataclass
class Run:
    """One run folder's records."""

    path: Path
    results: dict[str, Any]
    timing: dict[str, Any] = field(default_factory=dict)
    manifest: dict[str, Any] = field(default_factory=dict)

    @property
    def experiment(self) -> str:
        """The experiment's name as results.json records it (``sis``, ``scaling``, ...)."""
        return str(self.results.get("experiment", "?"))


#: the largest run record read (a results.json of a long sweep is a few megabytes).
MAX_BYTES = 256 << 20


def _read_json(path: Path, *, required: bool) -> dict[str, Any]:
    if path.exists() and not path.is_file():
        raise UserError(f"{path}: not a regular file (a folder or a device); not a run record")
    try:
        if path.is_file() and path.stat().st_size > MAX_BYTES:
            raise UserError(f"{path}: larger than {MAX_BYTES >> 20} MB; not a run record")
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        if required:
            raise UserError(f"{path}: no such file (is this a run folder?)") from None
        return {}
    except (OSError, UnicodeDecodeError) as exc:
        raise UserError(f"{path}: cannot read it ({exc})") from None
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        where = f":{exc.lineno}" if isinstance(exc, json.JSONDecodeError) else ""
        raise UserError(f"{path}{where}: not valid JSON ({exc})") from None
    if not isinstance(data, dict):
        raise UserError(f"{path}: expected a JSON object, found {type(data).__name__}")
    return data


def load_run(path: str | Path) -> Run:
    """Read a run folder (or its ``results.json``)."""
    folder = Path(path)
    if folder.name == "results.json":
        folder = folder.parent
    if not folder.is_dir():
        raise UserError(f"{folder}: not a run folder (no such folder)")
    results = _read_json(folder / "results.json", required=True)
    if "experiment" not in results:
        raise UserError(f"{folder / 'results.json'}: no \"experiment\" key; "
                        "not the results of a relrl experiment")
    timing = _read_json(folder / "timing.json", required=False)
    manifest = _read_json(folder / ".relrl-run.json", required=False)
    check_run(folder, results, timing, manifest)
    return Run(folder, results, timing, manifest)


# ---- formatting helpers ---------------------------------------------------------------------


def _f(x: Any, digits: int = 2) -> str:
    if x is None:
        return "—"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return f"{x:,}"
    if isinstance(x, float):
        return f"{x:,.{digits}f}"
    return str(x)


def table(header: list[str], rows: list[list[Any]]) -> str:
    """A Markdown table (values formatted by their type; every string shown as the text it
    is, unless the view marked it :class:`~relrl.markdown.Markdown`)."""
    lines = ["| " + " | ".join(map(text, header)) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(text(v if isinstance(v, str) else _f(v)) for v in row) + " |"
              for row in rows]
    return "\n".join(lines) + "\n"


def shown_command(command: str) -> str:
    """A run's command as a document shows it: an absolute output folder (a machine's own
    path, which says nothing of the numbers) as ``DIR``."""
    return re.sub(r"(--out[ =])/\S+", r"\1DIR", command)


def provenance(run: Run, label: str) -> str:
    """The line that says where the numbers come from."""
    from relrl.machine import describe

    command = run.manifest.get("command") or run.results.get("command")
    machine = (run.timing.get("machine_info") or run.results.get("machine_info")
               or {"machine": run.timing.get("machine"), "python": run.timing.get("python")})
    when = (run.manifest.get("ended") or run.manifest.get("started") or "")[:10]
    line = f"*From {code(f'{label}/results.json')}"
    if command:
        line += f", made by {code(shown_command(command))}"
    line += f" on {text(describe(machine))}" + (f", {text(when)}" if when else "")
    if run.results.get("partial"):
        line += " (**a partial run**: stopped before the end)"
    return line + ".*\n"


# ---- views ---------------------------------------------------------------------------------

View = Callable[[Run], str]
#: (experiment, view name) -> renderer. Each renderer returns the Markdown of its tables.
VIEWS: dict[tuple[str, str], View] = {}


def view(experiment: str, name: str) -> Callable[[View], View]:
    """Register a renderer for ``(experiment, name)``."""
    def register(fn: View) -> View:
        VIEWS[(experiment, name)] = fn
        return fn
    return register


#: (experiment, view name) -> renderer of several runs side by side (a block naming
#: ``path,path`` in a Markdown file).
MULTI_VIEWS: dict[tuple[str, str], Callable[[list[Run]], str]] = {}


def render_many(runs: list[Run], name: str, labels: list[str]) -> str:
    """The Markdown of one view of several runs side by side, with their provenance lines."""
    kinds = {r.experiment for r in runs}
    fn = MULTI_VIEWS.get((runs[0].experiment, name)) if len(kinds) == 1 else None
    if fn is None:
        raise UserError(f"no view {name!r} of several {'/'.join(sorted(kinds))} runs side by "
                        f"side (known: {', '.join(sorted(v for _, v in MULTI_VIEWS)) or 'none'})")
    return _ended(fn(runs)) + "\n" + "\n".join(provenance(r, lb) for r, lb in zip(runs, labels,
                                                                                    strict=True))


def render(run: Run, name: str, label: str | None = None) -> str:
    """The Markdown of one view of a run, with its provenance line."""
    fn = VIEWS.get((run.experiment, name))
    if fn is None:
        known = sorted(v for e, v in VIEWS if e == run.experiment)
        raise UserError(f"{run.path}: no view {name!r} of a {run.experiment!r} run "
                        f"(known: {', '.join(known) or 'none'})")
    return _ended(fn(run)) + "\n" + provenance(run, label or str(run.path))


def _ended(body: str) -> str:
    """A view's Markdown ending in a newline, so the provenance line after it is a paragraph
    of its own (not a row of the table above it)."""
    return body if body.endswith("\n") else body + "\n"


def render_report(paths: list[str | Path], out: Path, root: str | Path | None = None) -> str:
    """A whole results page: every view of every run, each in its block (links relative to
    ``out``'s folder), figures linked from the run folders.

    Raises:
        UserError: a run outside the document's tree (``root``, see :func:`tree_of`), or
            whose path a block marker cannot name.
    """
    import os

    tree = tree_of(out, root)
    parts = ["# Results\n\n",
             "Generated by `relrl report` from the runs named in each block; "
             "re-render with `relrl report --update` after new runs.\n"]
    for p in paths:
        run = load_run(p)
        rel = Path(os.path.relpath(run.path.resolve(), out.resolve().parent)).as_posix()
        _inside(tree, run.path, rel, str(out))
        names = [v for e, v in VIEWS if e == run.experiment and v != "short"]
        parts.append(f"\n## {TITLES.get(run.experiment, run.experiment)} ({code(rel)})\n")
        for name in names:
            parts.append(f"\n<!-- relrl-report {rel} {name} -->\n"
                         f"{render(run, name, rel)}<!-- /relrl-report -->\n")
        for png in sorted(run.path.glob("*.png")):
            parts.append(f"\n![{text(png.stem)}]({link(f'{rel}/{png.name}')})\n")
    return "".join(parts)


#: the characters a run's path may have in a block marker (no space, quote, bracket or ``-->``
#: to end the marker or the comment early, and nothing HTML or a shell reads specially).
MARKER_PATH = re.compile(r"[\w.@+=~/-]+")
#: the records of a run folder that a block reads.
_RECORDS = ("results.json", "timing.json", ".relrl-run.json")


def tree_of(md: str | Path, root: str | Path | None = None) -> Path:
    """The tree a Markdown file's blocks may read runs from: ``root`` when given, else the
    git work tree that holds the file, else the file's own folder."""
    if root is not None:
        return Path(root).resolve()
    folder = Path(md).resolve().parent
    for up in (folder, *folder.parents):
        if (up / ".git").exists():
            return up
    return folder


def _inside(tree: Path, folder: Path, named: str, where: str) -> None:
    """Refuse a run folder named ``named`` in a block that is absolute, is not a plain path,
    or (its records included, links followed) lies outside ``tree``."""
    if not MARKER_PATH.fullmatch(named) or named.startswith("/"):
        raise UserError(f"{where}: the run path {named!r} cannot be named in a block (a "
                        "relative path of letters, digits and . _ - / @ + = ~)")
    for path in (folder, *(folder / name for name in _RECORDS)):
        real = path.resolve()
        if not real.is_relative_to(tree):
            what = named if path == folder else f"{named}/{path.name}"
            raise UserError(f"{where}: {what} leads outside {tree}, the tree this "
                            "document's blocks may read runs from (--root DIR widens it)")


TITLES = {"sis": "Experiment 1: the learners in the Social Interactive Simulator",
          "exp2": "Experiment 2: gaze following and declarative pointing with fruits",
          "scaling": "Worlds that grow: the scaling benchmark"}


def _read_doc(md: Path) -> str:
    """A Markdown file's text (UTF-8; a byte that is not is one line naming its line)."""
    try:
        if md.stat().st_size > MAX_BYTES:
            raise UserError(f"{md}: larger than {MAX_BYTES >> 20} MB; not a document")
        data = md.read_bytes()
    except OSError as exc:
        raise UserError(f"{md}: cannot read it ({exc.strerror or exc})") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise UserError(f"{md}:{line}: byte 0x{data[exc.start]:02x} is not UTF-8 (relrl "
                        "reads and writes Markdown as UTF-8)") from None


def _line(m: re.Match[str]) -> int:
    return m.string.count("\n", 0, m.start()) + 1


def _blocks(md: Path, root: str | Path | None) -> list[tuple[re.Match[str], str]]:
    """Every block of ``md`` and what its runs render now. A block's runs must lie in the
    document's tree (:func:`tree_of`): a marker is text anyone may have written."""
    tree = tree_of(md, root)
    doc = _read_doc(md)
    out = []
    for m in BLOCK.finditer(doc):
        paths = m["path"].split(",")
        for p in paths:
            _inside(tree, md.parent / p, p, f"{md}:{_line(m)}")
        if len(paths) == 1:
            out.append((m, render(load_run(md.parent / paths[0]), m["view"], paths[0])))
        else:
            runs = [load_run(md.parent / p) for p in paths]
            out.append((m, render_many(runs, m["view"], paths)))
    return out


def stale_blocks(md: str | Path, root: str | Path | None = None) -> list[str]:
    """The blocks of a Markdown file that differ from what their source renders now (runs
    read from ``root``'s tree, see :func:`tree_of`)."""
    md = Path(md)
    return [f"{md}:{_line(m)}: {m['path']} {m['view']}"
            for m, fresh in _blocks(md, root) if m["body"] != fresh]


def update_file(md: str | Path, root: str | Path | None = None) -> int:
    """Re-render every block of a Markdown file in place (runs read from ``root``'s tree,
    see :func:`tree_of`); the number of blocks changed."""
    md = Path(md)
    doc = _read_doc(md)
    changed = 0
    pieces, last = [], 0
    for m, fresh in _blocks(md, root):
        pieces.append(doc[last:m.start("body")])
        pieces.append(fresh)
        changed += m["body"] != fresh
        last = m.end("body")
    pieces.append(doc[last:])
    if changed:
        from relrl.outdir import write_atomic

        write_atomic(md, "".join(pieces))
    return changed


# ---- Experiment 1 --------------------------------------------------------------------------


def _pm(mean: float | None, std: float | None) -> str:
    return "—" if mean is None else f"{mean:.2f} ± {std or 0:.2f}"


def _run1(s: dict[str, Any]) -> tuple[float | None, float | None]:
    c = s["curve"]
    return (c[1]["cgi_mean"], c[1]["cgi_std"]) if len(c) > 1 else (None, None)


@view("sis", "summary")
def _sis_summary(run: Run) -> str:
    r = run.results
    cfg, summary = r["config"], r["summary"]
    head = (f"{len(r['seeds'])} seed(s) ({', '.join(map(str, r['seeds']))}), "
            f"{cfg['points'] + 1} evaluation points (the first before learning) of "
            f"{cfg['eval_runs']} runs x {cfg['eval_steps']} time units, "
            f"{cfg['block']} learning units between points; caregiver {code(cfg['caregiver'])}"
            + (f", preset {code(cfg['preset'])}" if cfg.get("preset") else "") + ".\n\n")
    rows = []
    for name, s in summary.items():
        m1, s1 = _run1(s)
        last = s["curve"][-1]
        rows.append([name, _pm(m1, s1), _pm(last["cgi_mean"], last["cgi_std"]),
                     _f(s["cgi_literal_final"]),
                     f"{s['eye_contacts']['mean']:.1f} / {s['eye_contacts']['opportunities']}",
                     _f(round(s["memory"].get("positions", 0))), _f(s.get("states_met"), 0)])
    return head + table(["learner", "CGI after run 1", "CGI final", "final, Eq. 5 literally",
                         "eye contacts (first opportunities)", "memory (positions)",
                         "states met"], rows)


@view("sis", "short")
def _sis_short(run: Run) -> str:
    paper = run.results.get("paper", {})
    rows = []
    for name, s in run.results["summary"].items():
        m1, _ = _run1(s)
        rows.append([name, _f(m1), _f(s["cgi_final"]), f"{s['eye_contacts']['mean']:.0f}",
                     _f(round(s["memory"].get("positions", 0)))])
    mem = paper.get("memory_positions", {})
    rows.append([Markdown("*paper (2012)*"), "≈ 0.8 (all)", "C flat; Q, ETG rise",
                 "C most, Q fewest",
                 f"Q {_f(mem.get('qlearning'), 0)}; ETG {_f(mem.get('etg'), 0)}" if mem else "—"])
    return table(["learner", "CGI after run 1", "CGI final", "eye contacts", "positions"], rows)


@view("sis", "curves")
def _sis_curves(run: Run) -> str:
    """Each learner's CGI curve, point by point (mean over the seeds), before learning first."""
    rows = [[name, " ".join(f"{p['cgi_mean']:.2f}" for p in s["curve"])]
            for name, s in run.results["summary"].items()]
    return table(["learner", "CGI at each evaluation point (mean over the seeds)"], rows)


# ---- Experiment 2 --------------------------------------------------------------------------


@view("exp2", "table1")
def _exp2_table1(run: Run) -> str:
    r = run.results
    paper = r.get("paper", {}).get("table1", {})
    keys = sorted(k for k in r["summary"]
                  if (r["summary"][k].get("table1") or {}).get("all_executions"))
    if not keys:   # (only the readings of the time unit with naming executions have one)
        raise UserError(f"{run.path / 'results.json'}: no Table 1 in this run (symbolic "
                        "perception, or no naming executions)")
    outcomes = list(paper) or sorted({o for k in keys
                                      for o in r["summary"][k]["table1"]["all_executions"]})
    header = ["measure (%)", "paper"] + keys
    rows = []
    for o in outcomes:
        p = paper.get(o)
        row = [o.replace("_", " "), f"{p[0]} ± {p[1]}" if p else "—"]
        for k in keys:
            v = r["summary"][k]["table1"]["all_executions"].get(o)
            row.append(f"{v[0]:.2f} ± {v[1]:.2f}" if v else "—")
        rows.append(row)
    return table(header, rows)


@view("exp2", "fig6")
def _exp2_fig6(run: Run) -> str:
    keys = sorted(run.results["summary"])
    units = sorted({p["units"] for k in keys for p in run.results["summary"][k]["fig6"]})
    rows = []
    for u in units:
        row: list[Any] = [u]
        for k in keys:
            pt = next((p for p in run.results["summary"][k]["fig6"] if p["units"] == u), None)
            row.append(_pm(pt["cgi_mean"], pt["cgi_sd_over_seeds"]) if pt else "—")
        rows.append(row)
    return table(["learning units"] + [f"CGI {k}" for k in keys], rows)


@view("exp2", "confusions")
def _exp2_confusions(run: Run) -> str:
    """What the robot would have said of each fruit shown, before hearing its name (% of the
    presentations of that fruit; ``nothing``: no confident name yet), per learner."""
    rows = []
    for k in sorted(run.results["summary"]):
        confusion = run.results["summary"][k].get("confusion") or {}
        for shown, said in sorted(confusion.items()):
            total = sum(said.values())
            ranked = sorted(said.items(), key=lambda kv: (-kv[1], kv[0]))
            rows.append([k, shown, ", ".join(f"{name} {100 * n / total:.1f} %"
                                             for name, n in ranked) if total > 0 else "—"])
    if not rows:
        raise UserError(f"{run.path / 'results.json'}: no confusions in this run")
    return table(["learner / time unit", "fruit shown", "what the robot would have said"], rows)


@view("exp2", "short")
def _exp2_short(run: Run) -> str:
    r = run.results
    paper = r.get("paper", {}).get("table1", {})
    rows = []
    for k in sorted(r["summary"]):
        s = r["summary"][k]
        fig6 = s["fig6"]
        t1 = (s.get("table1") or {}).get("all_executions") or {}
        rows.append([k, _f(fig6[-1]["cgi_mean"]) if fig6 else "—",
                     f"{t1['success'][0]:.1f}" if "success" in t1 else "—"])
    if "success" in paper:
        rows.append([Markdown("*paper (2012)*"), "rises, then flat",
                     f"{paper['success'][0]}"])
    return table(["learner / time unit", "final CGI (Fig. 6)", "success rate % (Table 1)"],
                 rows)


# ---- relrl bench ------------------------------------------------------------------------


@view("bench", "summary")
def _bench_summary(run: Run) -> str:
    """What ``relrl bench --json FILE`` measured: rates and ratios, each beside its target."""
    r = run.results
    learners = r["learners"]
    rows: list[list[Any]] = [["one gateway call, one binding (median)",
                              f"{r['gateway_call_us']:.1f} µs", "—"]]
    for name in ("etg", "tg", "qlearning", "contingency"):
        if name in learners:
            f = learners[name]
            rows.append([f"{name}: learning steps/s on the simulator (calls per step)",
                         f"{f['steps_per_second']:,.0f} ({f['gateway_calls_per_step']:.2f})",
                         "tg ≥ 3,000; ≤ 1.5 calls" if name == "tg" else "≤ 1.5 calls"])
    etg = learners.get("etg", {})
    if "step_in_gateway_calls" in etg:
        rows.append(["ETG agent step, in gateway calls' worth of time",
                     f"{etg['step_in_gateway_calls']:.2f}", "≤ 3"])
    rows.append(["tg's step against ETG's (CPU time)", _f(r.get("tg_step_in_etg_steps")),
                 "≤ 2"])
    by_size = r.get("tg_step_by_size", {}).get("ratio", {})
    if by_size:
        big = max(by_size, key=int)
        rows.append([f"tg's learning step at P = {big} against P = 5",
                     f"{by_size[big]:.2f}", "≤ 1.5"])
    side = r.get("etg_prolog_side", {})
    if "cpu_us_per_step" in side and "inferences_per_step" in side:
        rows.append(["the Prolog side of an ETG step, plain swipl (inferences)",
                     f"{side['cpu_us_per_step']:.1f} µs ({side['inferences_per_step']:.0f})",
                     "—"])
    rows.append(["simulator step() alone, steps/s",
                 f"{r['sis_env_steps_per_second']['steps_per_second']:,.0f}", "—"])
    for key, label in (("monitor", "ETG steps/s with the live monitor, against without"),
                       ("recording", "a session's time units/s recording MCAP, against the "
                                     "trace alone")):
        part = r.get(key, {})
        if "ratio" in part:
            low, high = part.get("ratio_range", [None, None])
            spread = f" (pairs {low:.2f}–{high:.2f})" if low is not None else ""
            rows.append([label, f"{part['ratio']:.2f}{spread}", "≥ 0.9"])
    photos = r.get("perception", {})
    for key, label in (("fps_photos_320x240_cold", "perception, real photos 320x240, one "
                                                   "thread, frames/s"),
                       ("fps_photos_320x240_cold_2threads", "the same, two threads")):
        if key in photos:
            rows.append([label, f"{photos[key]:.1f}", "≥ 60"])
    met = sum(bool(v) for v in r.get("targets", {}).values())
    return (f"{r.get('cpus')} CPUs; {met} of {len(r.get('targets', {}))} targets met.\n\n"
            + table(["what", "measured", "target"], rows))


# ---- Worlds written in Prolog --------------------------------------------------------------


@view("worlds", "summary")
def _worlds_summary(run: Run) -> str:
    from relrl.worlds.experiment import worlds_table

    r = run.results
    cfg = r["config"]
    head = (f"{len(r['seeds'])} seed(s) ({', '.join(map(str, r['seeds']))}), "
            f"{cfg['episodes']} learning episodes on sizes "
            f"{', '.join(map(str, cfg['train_sizes']))}, greedy evaluations of "
            f"{cfg['eval_episodes']} episodes; a score is optimal / steps per episode (0 for "
            "a missed goal), the test sizes with no further learning.\n\n")
    return head + worlds_table(r)


@view("worlds", "short")
def _worlds_short(run: Run) -> str:
    """One row per world and task, one column per learner: the fraction of optimal on the
    training sizes and on the largest test size, with no learning, each with its worst
    seed."""
    r = run.results
    train, test = r["config"]["train_sizes"], r["config"]["test_sizes"]
    learners = list(dict.fromkeys(x["learner"] for x in r["summary"]))
    cells: dict[str, dict[str, str]] = {}
    for x in r["summary"]:
        row = cells.setdefault(f"{Path(x['world']).stem}: {x['task']}", {})
        big = x["test"][str(max(test))]
        worst = big.get("optimality_min")
        row[x["learner"]] = (f"{x['train_optimality']:.3f} ({x['train_optimality_min']:.3f})"
                             f" → {_f(big['optimality'], 3)}"
                             + (f" ({_f(worst, 3)})" if worst is not None else ""))
    rows = [[task] + [row.get(learner, "—") for learner in learners]
            for task, row in cells.items()]
    return (f"Fraction of optimal on {min(train)}–{max(train)} objects (worst seed) → on "
            f"{max(test)} objects with no learning (worst seed), mean of {len(r['seeds'])} "
            "seeds.\n\n"
            + table(["world: task", *learners], rows))


_CLOCK = {"process CPU time": "CPU", "wall": "wall-clock"}


@view("worlds", "cost")
def _worlds_cost(run: Run) -> str:
    return worlds_cost_table(run.timing)


def worlds_cost_table(timing: dict[str, Any]) -> str:
    """A worlds run's cost, one row per job measured (made without ``--no-speed``): the
    learning steps per second, a learning step's CPU cost at each size, its growth (the
    slope k of cost ∝ size^k over every size and over the test sizes alone) and a greedy
    episode's CPU cost at the largest test size."""
    rows, clocks = [], set()
    largest = None
    for t in timing.get("jobs", []):
        cost = t.get("step_cost_by_size")
        if not cost:
            continue
        clocks.add(cost.get("clock", "wall"))      # runs before the CPU clock: wall time
        sizes = cost["sizes"]
        greedy = (t.get("greedy_episode_cost_by_size") or {}).get("sizes") or {}
        big = max(greedy, key=int, default=None)
        largest = big if largest is None or big is None else max(largest, big, key=int)
        fit = cost.get("fit_sizes") or []
        rows.append([Path(t["world"]).stem, t["task"], t["learner"], t["seed"],
                     _f(t.get("learning_steps_per_second"), 0),
                     " / ".join(_f(cost["us_per_step"][str(s)], 0) for s in sizes),
                     _f(cost["cost_ratio"][str(sizes[-1])]),
                     _f(cost["size_ratio"][str(sizes[-1])]),
                     _f(cost.get("slope")),
                     (f"{_f(cost.get('fit_slope'))} ({fit[0]}–{fit[-1]})" if fit else "—"),
                     (f"{_f(greedy[big]['cpu_ms_per_episode'], 1)} ({big}: "
                      f"{_f(greedy[big]['steps'] / greedy[big]['episodes'], 1)} steps)"
                      if big else "—")])
    return table(["world", "task", "learner", "seed", "learning steps/s",
                  f"{' or '.join(sorted(_CLOCK.get(c, c) for c in clocks)) or 'CPU'} µs "
                  "per learning step by size", "cost ratio, largest / smallest",
                  "size ratio", "slope k (cost ∝ size^k)", "slope k over the test sizes",
                  "CPU ms per greedy episode, largest test size (its mean steps)"], rows)


_CLAIM_ROWS = {"after_first_run": "all three near 0.8 CGI after the first 500-unit run",
               "later": "then contingency flat; ETG and Q-learning rise to a plateau",
               "eye_contacts": "eye contacts: contingency most, Q-learning fewest"}


def _claim_figures(values: dict[str, dict[str, float]]) -> str:
    short = {"contingency": "C", "qlearning": "Q", "etg": "ETG"}
    parts = []
    for what, d in values.items():
        label = {"cgi_after_first_run": "run 1", "cgi_final": "final",
                 "eye_contacts_mean": "eye contacts"}.get(what, what)
        fmt = "{:.1f}" if what == "eye_contacts_mean" else "{:.2f}"
        parts.append(f"{label} " + ", ".join(f"{short.get(n, n)} {fmt.format(v)}"
                                             for n, v in sorted(d.items())))
    return "; ".join(parts)


def _claims_of(run: Run) -> dict[str, Any]:
    claims = run.results.get("claims")
    if not claims:
        raise UserError(f"{run.path / 'results.json'}: no \"claims\" (a run of an earlier "
                        "relrl, or without the paper's three learners)")
    return claims


def _sis_claims_side_by_side(runs: list[Run]) -> str:
    """The paper's three claims judged on each run (results.json's ``claims``), one column
    per run (its setting: ``fixed task`` or the preset)."""
    claims = [_claims_of(r) for r in runs]
    header = ["the paper's claim"] + [code(r.results['config'].get('preset') or 'fixed task')
                                      for r in runs]
    rows = []
    for key in [k for k in _CLAIM_ROWS if k in claims[0]] + \
            [k for k in claims[0] if k not in _CLAIM_ROWS]:
        row = [_CLAIM_ROWS.get(key, key)]
        for c in claims:
            if key not in c:
                row.append("—")
                continue
            verdict = {True: "**held**", False: "not held", None: "not judged"}[c[key]["held"]]
            row.append(Markdown(f"{verdict}: {text(_claim_figures(c[key]['values']))}"))
        rows.append(row)
    return table(header, rows)


MULTI_VIEWS[("sis", "claims")] = _sis_claims_side_by_side


@view("sis", "claims")
def _sis_claims(run: Run) -> str:
    """The paper's three claims judged on this run (results.json's ``claims``)."""
    return _sis_claims_side_by_side([run])


# ---- the scaling benchmark ----------------------------------------------------------------


def _sizes(rows: dict[str, Any]) -> list[str]:
    return sorted(rows, key=int)


@view("scaling", "summary")
def _scaling_summary(run: Run) -> str:
    r = run.results
    cfg, learn = r["config"], r["summary"]["learn"]
    head = (f"{len(r['seeds'])} seed(s), sizes {', '.join(map(str, cfg['sizes']))} toy "
            f"places; an evaluation every {cfg['block']:,} learning units ({cfg['eval_runs']} "
            f"runs of {cfg['eval_steps']} units), budget {cfg['budget']:,}, threshold CGI "
            f"{cfg['threshold']}.\n\n")
    rows = []
    for learner, by_size in learn.items():
        for size in _sizes(by_size):
            s = by_size[size]
            rows.append([learner, int(size), f"{s['reached']}/{s['seeds']}",
                         _f(s["steps_to_threshold"], 0), _f(s["cgi_final"]),
                         _f(s["memory_positions"], 0), _f(s.get("candidates_per_leaf"), 1)])
    return head + table(["learner", "places P", "reached 0.9", "learning units to 0.9 (mean)",
                         "final CGI", "memory (positions)", "candidate tests per leaf"], rows)


def _transfer_of(run: Run) -> tuple[dict[str, Any], str]:
    """A scaling run's transfer summary, and what was transferred, in words."""
    r = run.results
    transfer = r["summary"].get("transfer", {})
    if not transfer:
        raise UserError(f"{run.path / 'results.json'}: no transfer jobs in this run")
    kind = r["config"].get("transfer")
    what = {"sizes": f"learned at P = {r['config'].get('transfer_from')}, then acting with no "
                     "learning in each world", "places": "places held out while learning",
            "kinds": "toy kinds held out while learning"}.get(kind, str(kind))
    return transfer, what


@view("scaling", "transfer")
def _scaling_transfer(run: Run) -> str:
    transfer, what = _transfer_of(run)
    rows = []
    for learner, by_size in transfer.items():
        for size in _sizes(by_size):
            s = by_size[size]
            rows.append([learner, int(size), _f(s.get("cgi_trained")), _f(s.get("cgi_unseen")),
                         f"{s['seeds']}"])
    return (f"Zero-shot transfer ({text(what)}).\n\n"
            + table(["learner", "places P", "CGI trained", "CGI unseen", "seeds"], rows))


@view("scaling", "transfer-short")
def _scaling_transfer_short(run: Run) -> str:
    """Transfer in one row per learner: the CGI trained → unseen at each size."""
    transfer, what = _transfer_of(run)
    rows = []
    for learner, by_size in transfer.items():
        sizes = _sizes(by_size)
        rows.append([learner, what, ", ".join(sizes), " · ".join(
            f"{_f(by_size[p].get('cgi_trained'))} → {_f(by_size[p].get('cgi_unseen'))}"
            for p in sizes)])
    return table(["learner", "zero-shot transfer", "places P",
                  "CGI trained → unseen (no learning), per P"], rows)


@view("scaling", "short")
def _scaling_short(run: Run) -> str:
    learn = run.results["summary"]["learn"]
    rows = []
    for learner, by_size in learn.items():
        sizes = _sizes(by_size)
        reached = [f"{by_size[p]['reached']}/{by_size[p]['seeds']}" for p in sizes]
        memory = [_f(by_size[p]["memory_positions"], 0) for p in sizes]
        rows.append([learner, ", ".join(sizes), " · ".join(reached), " · ".join(memory)])
    return table(["learner", "places P", "seeds reaching CGI 0.9, per P", "memory (positions), "
                  "per P"], rows)
