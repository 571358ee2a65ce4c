"""``relrl experiment worlds``: learners x tasks x seeds in worlds written in Prolog.

Each job is one :func:`relrl.worlds.learn.learn_task` run (one world file, task, learner,
seed): a learning curve on the training sizes, an evaluation with no further learning on
each test size, memory, steps/s and the step cost by size. Jobs run in worker processes or
on Ray (:mod:`relrl.experiments.runner`), one Prolog engine each. Besides the jobs, the
world's stated optimum (optimal_steps/3) is checked against a breadth-first search on random
start states of the small sizes, and the check is written with the results.

Files: ``results.json`` (every number and the configuration; ``"partial": true`` when
stopped early, with the evaluation points of each job that had not finished, marked
partial, among the jobs and in curves.csv, and the summary of the jobs that finished),
``timing.json`` (wall clock, steps/s, the CPU cost of a step by size and its log-log
slope), ``summary.csv``
(per world, task and learner: the mean over seeds), ``curves.csv``, ``test.csv``,
``step_cost.csv``, ``optimal_check.csv``, ``curves.png``, ``transfer.png``,
``step_cost.png`` and ``policies/`` (every job's learned policy, readable Prolog that loads
into a world of any size: ``relrl learn WORLD --policy FILE``).
"""

from __future__ import annotations

import platform
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from relrl.experiments.results import pyplot_or_note, save_figure, skip_plots, write_csv
from relrl.experiments.runner import raise_kept, run_jobs
from relrl.learners import WORLDS, learners
from relrl.machine import machine_info
from relrl.outdir import write_atomic, write_json_atomic
from relrl.worlds.learn import LearnConfig, learn_task
from relrl.worlds.world import RULE_SECONDS

__all__ = ["OUTPUTS", "WorldsConfig", "run_worlds", "run_worlds_job", "worlds_table"]

#: the files and folders the experiment writes (checked for links before it runs).
OUTPUTS = ("results.json", "timing.json", "summary.csv", "curves.csv", "test.csv",
           "step_cost.csv", "optimal_check.csv", "curves.png", "transfer.png",
           "step_cost.png", "PLOTS.txt", "policies/")


@dataclass
class WorldsConfig:
    """Everything that determines a worlds run (written into results.json)."""

    worlds: list[str] = field(default_factory=list)           #: world files
    tasks: list[str] = field(default_factory=lambda: ["stack", "unstack", "on", "clear"])
    #: per world file, the tasks of ``tasks`` it declares (empty: every world runs them all)
    world_tasks: dict[str, list[str]] = field(default_factory=dict)
    learners: list[str] = field(default_factory=lambda: list(learners(WORLDS)))
    seeds: list[int] = field(default_factory=lambda: [0, 1, 2])
    learner_params: dict[str, dict[str, float]] = field(default_factory=dict)
    train_sizes: list[int] = field(default_factory=lambda: [3, 4, 5])
    test_sizes: list[int] = field(default_factory=lambda: [10, 20, 50])
    #: per world file, its own {"train": [...], "test": [...]} sizes (its sizes/2
    #: declarations, when no sizes were given), over train_sizes and test_sizes (then the
    #: union of the worlds')
    world_sizes: dict[str, dict[str, list[int]]] = field(default_factory=dict)
    episodes: int = 1000
    block: int = 100
    eval_episodes: int = 100
    updates: str = "episode"
    verify_sizes: list[int] = field(default_factory=lambda: [3, 4, 5])
    verify_states: int = 30
    rule_seconds: float = RULE_SECONDS      #: how long a rule of a world may run
    speed: bool = True                      #: measure each job's step cost by size
    restarts: int = 3                       #: fresh attempts after a failed check (learn.py)
    check_episodes: int = 1000              #: greedy episodes of an attempt's check

    def jobs(self) -> list[tuple[str, str, str, int]]:
        """Every (world, task, learner, seed) job."""
        return [(w, t, lr, s) for w in self.worlds for t in self.tasks_of(w)
                for lr in self.learners for s in self.seeds]

    def tasks_of(self, world: str) -> list[str]:
        """The tasks run in ``world``: those of ``tasks`` it declares."""
        return self.world_tasks.get(world, self.tasks)

    def sizes_of(self, world: str, which: str) -> list[int]:
        """The training (``which`` = ``"train"``) or test sizes of ``world``."""
        own = self.world_sizes.get(world, {}).get(which)
        if own is not None:
            return list(own)
        return list(self.train_sizes if which == "train" else self.test_sizes)

    def learn_config(self, world: str, task: str, learner: str, seed: int) -> LearnConfig:
        """The :class:`LearnConfig` of one job."""
        return LearnConfig(world=world, task=task, learner=learner,
                           params=dict(self.learner_params.get(learner, {})),
                           train_sizes=self.sizes_of(world, "train"),
                           test_sizes=self.sizes_of(world, "test"), episodes=self.episodes,
                           block=self.block, eval_episodes=self.eval_episodes, seed=seed,
                           updates=self.updates, rule_seconds=self.rule_seconds,
                           speed=self.speed, restarts=self.restarts,
                           check_episodes=self.check_episodes)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (world files by name: the folder is the machine's)."""
        out = asdict(self)
        out["worlds"] = [Path(w).name for w in self.worlds]
        out["world_tasks"] = {Path(w).name: ts for w, ts in self.world_tasks.items()}
        out["world_sizes"] = {Path(w).name: ss for w, ss in self.world_sizes.items()}
        return out


def run_worlds_job(config: WorldsConfig, world: str, task: str, learner: str, seed: int, *,
                   report: Any = None) -> dict[str, Any]:
    """One job: :func:`learn_task` of (world, task, learner, seed); the learned policy comes
    back as text (``policy``), for the run folder's ``policies/``. A job that fails reports
    the policy it had saved (``{"kind": "policy", "text": ...}``, before each evaluation)
    before its error goes on, and each evaluation point comes after the policy it
    evaluated, so that a job stopped by a signal or an error keeps its policy too."""
    import tempfile

    from relrl.errors import RelrlError

    with tempfile.TemporaryDirectory(prefix="relrl-worlds-") as tmp:
        path = Path(tmp) / "policy.pl"
        sent = [""]

        def send(event: dict[str, Any]) -> None:
            if event.get("kind") == "point" and path.is_file():
                text = path.read_text(encoding="utf-8")
                if text != sent[0]:
                    report({"kind": "policy", "text": text})
                    sent[0] = text
            report(event)

        try:
            result = learn_task(config.learn_config(world, task, learner, seed),
                                report=send if report is not None else None,
                                policy_out=path)
        except RelrlError:
            if report is not None and path.is_file():
                report({"kind": "policy", "text": path.read_text(encoding="utf-8")})
            raise
        result["policy"] = path.read_text(encoding="utf-8")
    return result


def verify_job(config: WorldsConfig, world: str, task: str, *, report: Any = None
               ) -> dict[str, Any]:
    """The world's optimal_steps/3 against a breadth-first search (seeded, per size)."""
    from relrl.learners import make_world_learner
    from relrl.worlds.world import World

    rows = []
    with World(world, rule_seconds=config.rule_seconds) as w:
        if not w.optimal_known:
            return {"world": Path(world).name, "task": task, "rows": [], "stated": False}
        w.attach(make_world_learner("qtable"), 0)
        for size in config.verify_sizes:
            pairs = w.verify_optimal(task, size, config.verify_states)
            searched = [p for p in pairs if p[1] is not None]
            rows.append({"size": size, "states": len(pairs), "searched": len(searched),
                         "agree": sum(1 for a, b in searched if a == b)})
    return {"world": Path(world).name, "task": task, "rows": rows, "stated": True}


def _label(args: tuple) -> str:
    if len(args) == 3:
        return f"check {Path(args[1]).stem} {args[2]}"
    _, world, task, learner, seed = args
    return f"{Path(world).stem} {task} {learner} seed {seed}"


def _job(*args: Any, report: Any = None) -> dict[str, Any]:
    if len(args) == 3:
        return verify_job(*args, report=report)
    return run_worlds_job(*args, report=report)


def run_worlds(config: WorldsConfig, out_dir: str | Path, *, workers: int = 1,
               engine: str = "local", address: str | None = None
               ) -> tuple[dict[str, Any], list[Path]]:
    """Run every job and write the outputs to ``out_dir``; stopped by a signal or a failing
    job, it writes what finished (``"partial": true``)."""
    from relrl import __version__

    out = Path(out_dir)
    checks = [(config, w, t) for w in config.worlds for t in config.tasks_of(w)]
    tasks = checks + [(config, *job) for job in config.jobs()]
    outcome = run_jobs(_job, tasks, workers=workers, engine=engine, address=address,
                       units=config.episodes // config.block + 1, label=_label)
    jobs, timings, verified = [], [], []
    policies: dict[str, str] = {}
    for task, result, events in zip(tasks, outcome.results, outcome.events, strict=True):
        if result is None:
            if len(task) != 3:
                unfinished = _unfinished(task, events)
                jobs += unfinished
                kept = [ev["text"] for ev in events if ev.get("kind") == "policy"]
                if unfinished and kept:
                    policies[_policy_name(unfinished[0])] = kept[-1]
            continue
        if len(task) == 3:
            verified.append(result)
            continue
        timings.append({"world": result["world"], "task": result["task"],
                        "learner": result["learner"], "seed": result["seed"],
                        **result.pop("timing")})
        policies[_policy_name(result)] = result.pop("policy")
        jobs.append(result)
    results = {"experiment": "worlds", "relrl_version": __version__,
               "config": config.to_dict(), "seeds": config.seeds,
               "partial": not outcome.complete,
               "summary": summarize([j for j in jobs if not j.get("partial")], config),
               "optimal_check": verified, "jobs": jobs}
    if outcome.interrupted:
        results["interrupted_by"] = outcome.interrupted
    if outcome.error:
        results["error"] = outcome.error
    timing = {"wall_seconds": outcome.seconds, "workers": workers, "engine": engine,
              "python": platform.python_version(), "machine_info": machine_info(),
              "jobs": timings}
    files = write_outputs(out, results, timing)
    files += [write_atomic(out / "policies" / name, text) for name, text in policies.items()]
    if outcome.error:
        raise_kept(outcome.error, out)
    return results, files


def _unfinished(task: tuple, events: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """A job that did not finish, as the evaluation points it reported (none: nothing),
    marked ``"partial": true``: in ``jobs`` and curves.csv, not in the summary (its policy,
    the last one it saved, in ``policies/`` as a finished job's)."""
    curve = [ev["entry"] for ev in events if ev.get("kind") == "point"]
    if not curve:
        return []
    _, world, name, learner, seed = task
    return [{"world": Path(world).name, "task": name, "learner": learner, "seed": seed,
             "curve": curve, "test": {}, "final": curve[-1],
             "memory": {"positions": curve[-1]["memory_positions"]}, "partial": True}]


def _policy_name(job: dict[str, Any]) -> str:
    """``policies/WORLD-TASK-LEARNER-sSEED.pl`` (the task's name without arguments)."""
    task = job["task"].split("(")[0]
    return f"{Path(job['world']).stem}-{task}-{job['learner']}-s{job['seed']}.pl"


def _mean(xs: list[float | None]) -> float | None:
    vals = [x for x in xs if x is not None]
    return sum(vals) / len(vals) if vals else None


def summarize(jobs: list[dict[str, Any]], config: WorldsConfig) -> list[dict[str, Any]]:
    """Per (world, task, learner): means over seeds of the final training-size evaluation,
    of each test size, of memory; and the worst seed's final optimality."""
    rows = []
    keys = sorted({(j["world"], j["task"], j["learner"]) for j in jobs})
    for world, task, learner in keys:
        js = [j for j in jobs if (j["world"], j["task"], j["learner"]) == (world, task,
                                                                           learner)]
        row = {"world": world, "task": task, "learner": learner, "seeds": len(js),
               "train_optimality": _mean([j["final"]["optimality"] for j in js]),
               "train_optimality_min": min(j["final"]["optimality"] for j in js),
               "train_success": _mean([j["final"]["success"] for j in js]),
               "train_success_min": min(j["final"]["success"] for j in js),
               "memory_positions": _mean([j["memory"]["positions"] for j in js]),
               "episodes_to_095": _mean([_first(j["curve"], 0.95) for j in js]),
               # restarts (learn.py): the seeds learned again, the attempts after the first
               "restarted_seeds": sum(len(j.get("attempts", ())) > 1 for j in js),
               "restarts": sum(max(0, len(j.get("attempts", ())) - 1) for j in js),
               "test": {}}
        for size in config.test_sizes:
            vals = [j["test"][str(size)] for j in js if str(size) in j["test"]]
            row["test"][str(size)] = {
                "optimality": _mean([v["optimality"] for v in vals]),
                "optimality_min": min((v["optimality"] for v in vals), default=None),
                "success": _mean([v["success"] for v in vals]),
                "success_min": min((v["success"] for v in vals), default=None)}
        rows.append(row)
    return rows


def _first(curve: list[dict[str, Any]], level: float) -> int | None:
    """Learning episodes at the first evaluation at or above ``level`` (None: never)."""
    return next((c["episodes"] for c in curve if (c["optimality"] or 0) >= level), None)


def _csv(path: Path, header: list[str], rows: list[list[Any]]) -> Path:
    return write_csv(path, header, [["" if v is None else (f"{v:.6g}" if isinstance(v, float)
                                                          else v) for v in row]
                                    for row in rows])


def write_outputs(out: Path, results: dict[str, Any], timing: dict[str, Any]) -> list[Path]:
    """results.json, timing.json, the CSVs and the plots; returns the files written."""
    sizes = results["config"]["test_sizes"]
    files = [write_json_atomic(out / "results.json", results),
             write_json_atomic(out / "timing.json", timing)]
    files.append(_csv(out / "summary.csv",
                      ["world", "task", "learner", "seeds", "train_optimality",
                       "train_optimality_min", "train_success", "episodes_to_095",
                       "memory_positions",
                       *(f"test_{s}_{k}" for s in sizes
                         for k in ("optimality", "optimality_min", "success_min"))],
                      [[r["world"], r["task"], r["learner"], r["seeds"],
                        r["train_optimality"], r["train_optimality_min"], r["train_success"],
                        r["episodes_to_095"], r["memory_positions"],
                        *(r["test"][str(s)].get(k) for s in sizes
                          for k in ("optimality", "optimality_min", "success_min"))]
                       for r in results["summary"]]))
    files.append(_csv(out / "curves.csv",
                      ["world", "task", "learner", "seed", "point", "episodes",
                       "learning_steps", "optimality", "success", "memory_positions"],
                      [[j["world"], j["task"], j["learner"], j["seed"], c["point"],
                        c["episodes"], c["learning_steps"], c["optimality"], c["success"],
                        c["memory_positions"]] for j in results["jobs"] for c in j["curve"]]))
    files.append(_csv(out / "test.csv",
                      ["world", "task", "learner", "seed", "size", "optimality", "success",
                       "steps", "optimal_steps"],
                      [[j["world"], j["task"], j["learner"], j["seed"], int(s),
                        v["optimality"], v["success"], v["steps"], v["optimal_steps"]]
                       for j in results["jobs"] for s, v in j["test"].items()]))
    files.append(_csv(out / "step_cost.csv",
                      ["world", "task", "learner", "seed", "size", "cpu_us_per_step",
                       "cost_ratio", "size_ratio", "slope", "fit_slope",
                       "learning_steps_per_second"],
                      [[t["world"], t["task"], t["learner"], t["seed"], int(s),
                        t["step_cost_by_size"]["us_per_step"][s],
                        t["step_cost_by_size"]["cost_ratio"][s],
                        t["step_cost_by_size"]["size_ratio"][s],
                        t["step_cost_by_size"].get("slope"),
                        t["step_cost_by_size"].get("fit_slope"),
                        t["learning_steps_per_second"]]
                       for t in timing["jobs"] if "step_cost_by_size" in t
                       for s in t["step_cost_by_size"]["us_per_step"]]))
    files.append(_csv(out / "optimal_check.csv",
                      ["world", "task", "size", "states", "searched", "agree"],
                      [[v["world"], v["task"], r["size"], r["states"], r["searched"],
                        r["agree"]] for v in results["optimal_check"] for r in v["rows"]]))
    files += plot(out, results, timing) if not results.get("partial") else skip_plots(out)
    return files


def plot(out: Path, results: dict[str, Any], timing: dict[str, Any]) -> list[Path]:
    """Learning curves, transfer and step cost as PNG files (a note without matplotlib)."""
    plt, note = pyplot_or_note(out)
    if plt is None:
        return note
    files = []
    groups = sorted({(j["world"], j["task"]) for j in results["jobs"]})
    fig, axes = plt.subplots(1, max(1, len(groups)), figsize=(4 * max(1, len(groups)), 3.2),
                             squeeze=False)
    for ax, (world, task) in zip(axes[0], groups, strict=False):
        for learner in results["config"]["learners"]:
            js = [j for j in results["jobs"] if (j["world"], j["task"], j["learner"]) ==
                  (world, task, learner)]
            if not js:
                continue
            xs = [c["episodes"] for c in js[0]["curve"]]
            ys = [_mean([j["curve"][i]["optimality"] for j in js if i < len(j["curve"])])
                  for i in range(len(xs))]
            ax.plot(xs, ys, marker=".", label=learner)
        ax.set_title(f"{Path(world).stem}: {task}", fontsize=9)
        ax.set_xlabel("learning episodes")
        ax.set_ylim(0, 1.05)
        ax.axhline(0.95, color="grey", lw=0.5, ls="--")
    axes[0][0].set_ylabel("greedy: fraction of optimal")
    axes[0][0].legend(fontsize=8)
    fig.tight_layout()
    files.append(save_figure(fig, out / "curves.png", dpi=120))
    fig, ax = plt.subplots(figsize=(5, 3.2))
    sizes = results["config"]["test_sizes"]
    for r in results["summary"]:
        ax.plot(sizes, [r["test"][str(s)]["optimality"] for s in sizes], marker="o",
                label=f"{Path(r['world']).stem} {r['task']} {r['learner']}")
    ax.set_xlabel("blocks (objects), no further learning")
    ax.set_ylabel("fraction of optimal")
    ax.set_ylim(0, 1.05)
    ax.axhline(0.9, color="grey", lw=0.5, ls="--")
    ax.legend(fontsize=6)
    fig.tight_layout()
    files.append(save_figure(fig, out / "transfer.png", dpi=120))
    fig, ax = plt.subplots(figsize=(5, 3.2))
    for t in timing["jobs"]:
        cost = t.get("step_cost_by_size")
        if cost and t["seed"] == results["seeds"][0]:
            xs = cost["sizes"]
            ax.plot(xs, [cost["cost_ratio"][str(s)] for s in xs], marker=".",
                    label=f"{Path(t['world']).stem} {t['task']} {t['learner']}")
    if timing["jobs"]:
        xs = results["config"]["train_sizes"][:1] + results["config"]["test_sizes"]
        ax.plot(xs, [s / xs[0] for s in xs], color="black", ls="--", label="linear")
    ax.set_xlabel("objects")
    ax.set_ylabel("learning-step CPU cost / smallest size's")
    ax.legend(fontsize=6)
    fig.tight_layout()
    files.append(save_figure(fig, out / "step_cost.png", dpi=120))
    return files


def worlds_table(results: dict[str, Any]) -> str:
    """The summary as a Markdown table (what ``relrl report``'s worlds view renders): per
    size the mean over seeds of the fraction of optimal and, in brackets, the worst seed's;
    a share of greedy episodes that reached the goal below 1 in any seed is marked."""
    from relrl.markdown import text

    sizes = results["config"]["test_sizes"]
    train = results["config"]["train_sizes"]
    own = {w: ss["train"] for w, ss in results["config"].get("world_sizes", {}).items()}
    mixed = len({tuple(ts) for ts in own.values()}) > 1
    span = "training sizes" if mixed else f"sizes {min(train)}–{max(train)}"
    head = (f"| world | task | learner | seeds | of optimal, {span} "
            "(worst seed) | " + " | ".join(f"size {s} (worst)" for s in sizes)
            + " | all reached the goal | episodes to 0.95 | positions |")
    lines = [head, "|" + "---|" * (9 + len(sizes) - 1)]
    for r in results["summary"]:
        tests = [r["test"][str(s)] for s in sizes]
        reached = [t.get("success_min") for t in tests]
        if any(x is None for x in reached):
            all_reached = "—"
        elif all(x >= 1 for x in reached):
            all_reached = "yes"
        else:
            all_reached = "no: worst " + ", ".join(_f(x) for x in reached)
        lines.append(
            f"| {text(Path(r['world']).stem)} | {text(r['task'])} | {text(r['learner'])} | "
            f"{r['seeds']}{_restarted(r)} | "
            + (f"{min(own[r['world']])}–{max(own[r['world']])}: "
               if mixed and r["world"] in own else "")
            + f"{_f(r['train_optimality'])} ({_f(r['train_optimality_min'])}) | "
            + " | ".join(f"{_f(t['optimality'])} ({_f(t.get('optimality_min'))})"
                         for t in tests)
            + f" | {all_reached} | {_f(r['episodes_to_095'], 0)} | "
            f"{_f(r['memory_positions'], 0)} |")
    return "\n".join(lines)


def _restarted(row: dict[str, Any]) -> str:
    """`` (N learned again)`` when N seeds restarted (none: nothing)."""
    n = row.get("restarted_seeds", 0)
    return f" ({n} learned again)" if n else ""


def _f(x: float | None, digits: int = 3) -> str:
    return "—" if x is None else f"{x:.{digits}f}"
