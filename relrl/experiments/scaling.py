"""The scaling benchmark: every learner in worlds that grow, and zero-shot transfer.

For each world size ``P`` (toy places; 5, 9, 17, 33 by default), learner and seed, one *job*
learns in the world (:class:`~relrl.sim.world.World`, its domain generated) and is evaluated
every ``block`` learning time units by the paper's protocol (:func:`relrl.sim.evaluate`,
``eval_runs`` runs of ``eval_steps`` time units, no learning, the learner unchanged). It
stops after ``budget`` learning time units, or earlier once the CGI has stayed at or above
``threshold`` for ``patience`` evaluations in a row (``patience`` 0: always the whole
budget). Measured: time units to CGI >= ``threshold`` (the first evaluation that reaches
it; ``None`` when none does within the budget), the final CGI (relrl's and Eq. 5's literal
reading), memory in positions after learning, distinct states met.

A *transfer* job learns with some places held out (``holdout`` of them, spread evenly along
the table; the caregiver's placement weight 0, so no toy is ever put there) or, with
``transfer="kinds"``, with only half of the toy kinds; then it is evaluated, without
learning, on the trained places and on the unseen ones (zero-shot). With
``transfer="sizes"`` (cross-size transfer, the classic claim of relational RL) it learns in
the world of ``transfer_from`` places, saves its policy, and the policy is loaded into a
fresh agent in each world of ``transfer_sizes`` and evaluated there with no further
learning. A policy loads only where it is tied to nothing the worlds differ in: tg's names
its relations and language bias (no place), so it loads in every world of the family; a
propositional learner's names the features and responses of its world, and its row says so
(``error``) instead of a CGI.

Wall-clock figures (steps/s) go to timing.json; results.json holds every other number and
the full configuration, byte-identical for the same configuration and seeds on any engine.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from relrl.learners import DOMAINS, learners
from relrl.sim.world import World

__all__ = ["ScalingConfig", "held_out_places", "run_scaling_job"]


@dataclass
class ScalingConfig:
    """Everything that determines a scaling run (written into results.json)."""

    learners: list[str] = field(default_factory=lambda: list(learners(DOMAINS)))
    sizes: list[int] = field(default_factory=lambda: [5, 9, 17, 33])
    seeds: list[int] = field(default_factory=lambda: [0, 1, 2])
    #: World fields besides ``places`` (colours, kinds, toys, scene, field).
    world: dict[str, Any] = field(default_factory=dict)
    caregiver: str = "paper"
    caregiver_params: dict[str, Any] = field(default_factory=dict)
    learner_params: dict[str, dict[str, float]] = field(default_factory=dict)
    budget: int = 60_000             #: learning time units at most
    block: int = 2_000               #: learning time units between evaluations
    eval_runs: int = 10
    eval_steps: int = 300
    threshold: float = 0.9
    patience: int = 2                #: stop after this many evaluations >= threshold (0: never)
    eval_policy: str = "behaviour"
    #: seconds one control step may run before the run stops (a rule that never ends); the
    #: robot's own default is 10 s, batch runs on a loaded machine need more room.
    timeout: float = 60.0
    transfer: str = "places"         #: places | kinds | sizes | none
    transfer_sizes: list[int] = field(default_factory=lambda: [5, 9, 17, 33])
    transfer_from: int = 5           #: with transfer "sizes": the world learned in
    holdout: float = 0.4             #: share of places (or kinds) held out for transfer

    def world_of(self, size: int) -> World:
        """The world of one size."""
        return World(**{**self.world, "places": size})

    def jobs(self) -> list[tuple[str, int, int, str]]:
        """Every (learner, size, seed, kind) job, kind ``learn`` or ``transfer``."""
        out = [(lr, size, seed, "learn") for size in self.sizes for lr in self.learners
               for seed in self.seeds]
        if self.transfer == "sizes":
            out += [(lr, self.transfer_from, seed, "transfer") for lr in self.learners
                    for seed in self.seeds]
        elif self.transfer != "none":
            out += [(lr, size, seed, "transfer") for size in self.transfer_sizes
                    for lr in self.learners for seed in self.seeds]
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form, with each size's world and caregiver fully resolved."""
        out = asdict(self)
        out["worlds"] = {str(s): self.world_of(s).to_dict() for s in self.sizes}
        out["caregiver_resolved"] = {
            str(s): self.world_of(s).caregiver_params(self.caregiver_params,
                                                      self.caregiver).to_dict()
            for s in self.sizes}
        return out


def held_out_places(places: tuple[str, ...], share: float) -> tuple[str, ...]:
    """``round(share * len(places))`` places (at least 1, at most all but 1), spread evenly."""
    n = len(places)
    k = min(n - 1, max(1, round(share * n)))
    return tuple(places[int((i + 0.5) * n / k)] for i in range(k))


def _domain(world: Any) -> str:
    """The world's domain file in this process's temporary folder (same text everywhere)."""
    return str(world.write_domain(Path(tempfile.gettempdir()) / "relrl-worlds"))


def _transfer_split(config: ScalingConfig, world: Any) -> dict[str, Any]:
    """What a transfer job trains on and evaluates on."""
    if config.transfer == "kinds":
        kinds = world.kind_names
        unseen = kinds[len(kinds) - max(1, round(config.holdout * len(kinds))):]
        seen = tuple(k for k in kinds if k not in unseen)
        return {"mode": "kinds", "trained": list(seen), "unseen": list(unseen),
                "learn": {"toy_kinds": seen}, "eval_seen": ({"toy_kinds": seen}, None),
                "eval_unseen": ({"toy_kinds": unseen}, None)}
    places = world.layout.toy_places
    unseen = held_out_places(places, config.holdout)
    seen = tuple(p for p in places if p not in unseen)
    return {"mode": "places", "trained": list(seen), "unseen": list(unseen),
            "learn": {"placement": {p: 1.0 for p in seen}},
            "eval_seen": ({}, seen), "eval_unseen": ({}, unseen)}


def run_scaling_job(config: ScalingConfig, learner: str, size: int, seed: int,
                    kind: str = "learn", *,
                    report: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """One learner in one world with one seed: learning curve (and transfer).

    ``report`` receives a ``{"kind": "point", ...}`` event per evaluation point.
    Returns a JSON-ready dict; wall-clock figures under ``"timing"``.
    """
    import time

    from relrl.experiments.protocol import Session, point_summary

    world = config.world_of(size)
    split = (_transfer_split(config, world) if kind == "transfer" and config.transfer != "sizes"
             else None)
    learn_params = dict(config.caregiver_params)
    eval_params = dict(config.caregiver_params)
    sequence = None
    if split is not None:
        learn_params.update(split["learn"])
        eval_params.update(split["eval_seen"][0])
        sequence = split["eval_seen"][1]
    learn_seconds = 0.0
    with Session(_domain(world), learner, config.learner_params.get(learner, {}), seed,
                 world=world, caregiver=config.caregiver, caregiver_params=learn_params,
                 eval_caregiver_params=eval_params, eval_steps=config.eval_steps,
                 eval_policy=config.eval_policy, timeout=config.timeout) as session:
        curve: list[dict[str, Any]] = []
        reached, streak = None, 0
        points = config.budget // config.block
        for point in range(points + 1):
            if point > 0:
                t0 = time.perf_counter()
                session.learn(config.block)
                learn_seconds += time.perf_counter() - t0
            ev = session.evaluate(config.eval_runs, sequence=sequence)
            entry = {"point": point, "learning_steps": session.learned,
                     "cgi_mean": ev.cgi_mean, "cgi_literal_mean": ev.cgi_literal_mean,
                     **point_summary(ev), "memory_positions": session.memory()["positions"]}
            curve.append(entry)
            if report is not None:
                report({"kind": "point", "point": point, "entry": entry})
            if ev.cgi_mean >= config.threshold:
                streak += 1
                if reached is None:
                    reached = session.learned
            else:
                streak = 0
            if config.patience and streak >= config.patience:
                break
        result: dict[str, Any] = {
            "learner": learner, "size": size, "seed": seed, "kind": kind,
            "curve": curve, "steps_to_threshold": reached,
            "learning_steps": session.learned,
            "cgi_final": curve[-1]["cgi_mean"],
            "cgi_literal_final": curve[-1]["cgi_literal_mean"],
            "memory": session.memory(), "states_met": session.states_met(),
            "learning": session.learning_summary(),
        }
        if kind == "transfer" and config.transfer == "sizes":
            result["transfer"] = _across_sizes(config, session, learner, seed,
                                               curve[-1]["cgi_mean"])
        elif split is not None:
            unseen_params = {**config.caregiver_params, **split["eval_unseen"][0]}
            session.eval_caregiver_params = unseen_params
            ev = session.evaluate(config.eval_runs, sequence=split["eval_unseen"][1])
            result["transfer"] = {
                "mode": split["mode"], "trained": split["trained"], "unseen": split["unseen"],
                "cgi_trained": curve[-1]["cgi_mean"], "cgi_unseen": ev.cgi_mean,
                "cgi_literal_unseen": ev.cgi_literal_mean, "cgi_unseen_runs": ev.cgi}
        timing = session.timing()
        timing["learning_seconds"] = learn_seconds
        timing["learning_steps_per_second"] = (session.learned / learn_seconds
                                               if learn_seconds else 0.0)
        result["timing"] = timing
        return result


def _across_sizes(config: ScalingConfig, session: Any, learner: str, seed: int,
                  cgi_trained: float) -> dict[str, Any]:
    """The learned policy of ``session`` loaded into a fresh agent in each world of
    ``transfer_sizes`` and evaluated there, no learning (cross-size transfer)."""
    from relrl.errors import PolicyError
    from relrl.experiments.protocol import Session

    by_size: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="relrl-transfer-") as tmp:
        policy = session.learner.save(Path(tmp) / f"{learner}-policy",
                                      f"relrl policy: {learner}, P={config.transfer_from}, "
                                      f"seed {seed}")
        for size in config.transfer_sizes:
            world = config.world_of(size)
            with Session(_domain(world), learner, config.learner_params.get(learner, {}),
                         seed, world=world, caregiver=config.caregiver,
                         caregiver_params=config.caregiver_params,
                         eval_steps=config.eval_steps, eval_policy=config.eval_policy,
                         timeout=config.timeout) as target:
                try:
                    target.learner.load(policy)
                except PolicyError as exc:
                    by_size[str(size)] = {"cgi": None, "cgi_literal": None,
                                          "error": str(exc).replace(str(policy), "the policy")}
                    continue
                ev = target.evaluate(config.eval_runs)
                by_size[str(size)] = {"cgi": ev.cgi_mean, "cgi_literal": ev.cgi_literal_mean,
                                      "cgi_runs": ev.cgi,
                                      "memory_positions": target.memory()["positions"]}
    unseen = [r["cgi"] for s, r in by_size.items()
              if int(s) != config.transfer_from and r["cgi"] is not None]
    return {"mode": "sizes", "trained": [config.transfer_from],
            "unseen": [s for s in config.transfer_sizes if s != config.transfer_from],
            "cgi_trained": cgi_trained,
            "cgi_unseen": sum(unseen) / len(unseen) if unseen else None,
            "by_size": by_size}


def summarize(jobs: list[dict[str, Any]], config: ScalingConfig) -> dict[str, Any]:
    """Per learner and size: means over seeds (``None`` where no seed reached the threshold;
    ``reached`` counts the seeds that did)."""
    import numpy as np

    def mean(xs: list[float | None]) -> float | None:
        xs = [x for x in xs if x is not None]
        return float(np.mean(xs)) if xs else None

    out: dict[str, Any] = {"learn": {}, "transfer": {}}
    for kind in ("learn", "transfer"):
        for learner in config.learners:
            rows = {}
            for size in config.sizes:
                mine = [j for j in jobs if (j["learner"], j["size"], j["kind"]) ==
                        (learner, size, kind)]
                if not mine:
                    continue
                steps = [j["steps_to_threshold"] for j in mine
                         if j["steps_to_threshold"] is not None]
                row = {"seeds": len(mine), "reached": len(steps),
                       "steps_to_threshold": mean(steps),
                       "steps_to_threshold_max": max(steps) if steps else None,
                       "cgi_final": mean([j["cgi_final"] for j in mine]),
                       "cgi_literal_final": mean([j["cgi_literal_final"] for j in mine]),
                       "memory_positions": mean([j["memory"]["positions"] for j in mine]),
                       # a relational learner's candidate tests per leaf (None for others)
                       "candidates_per_leaf": mean([j["memory"]["candidates"]
                                                    / j["memory"]["leaves"] for j in mine
                                                    if "candidates" in j["memory"]
                                                    and j["memory"].get("leaves")]),
                       "candidates_max": max((j["memory"]["candidates_max"] for j in mine
                                              if "candidates_max" in j["memory"]),
                                             default=None),
                       "states_met": mean([j["states_met"] for j in mine]),
                       "learning_steps": mean([j["learning_steps"] for j in mine]),
                       "partial": any(j.get("partial", False) for j in mine)}
                if kind == "transfer":
                    tr = [j["transfer"] for j in mine if "transfer" in j]
                    row.update({"cgi_trained": mean([t["cgi_trained"] for t in tr]),
                                "cgi_unseen": mean([t["cgi_unseen"] for t in tr]),
                                "unseen": tr[0]["unseen"] if tr else None})
                rows[str(size)] = row
            if rows:
                out[kind][learner] = rows
    if config.transfer == "sizes":
        out["transfer"] = _sizes_summary(jobs, config, mean)
    return out


def _sizes_summary(jobs: list[dict[str, Any]], config: ScalingConfig,
                   mean: Callable[[list[float | None]], float | None]) -> dict[str, Any]:
    """Cross-size transfer, per learner and target size: the CGI where the policies were
    learned (``cgi_trained``) and in the target world, no learning (``cgi_unseen``)."""
    out: dict[str, Any] = {}
    for learner in config.learners:
        mine = [j["transfer"] for j in jobs if (j["learner"], j["kind"]) ==
                (learner, "transfer") and "transfer" in j]
        if not mine:
            continue
        rows = {}
        for size in config.transfer_sizes:
            got = [t["by_size"][str(size)] for t in mine if str(size) in t["by_size"]]
            cgis = [g["cgi"] for g in got]
            row = {"seeds": len(got), "from": config.transfer_from,
                   "cgi_trained": mean([t["cgi_trained"] for t in mine]),
                   "cgi_unseen": mean(cgis),
                   "cgi_unseen_min": min((c for c in cgis if c is not None), default=None),
                   "unseen": [str(size)], "partial": False}
            errors = sorted({g["error"] for g in got if g.get("error")})
            if errors:
                row["errors"] = errors
            rows[str(size)] = row
        out[learner] = rows
    return out


def growth(summary: dict[str, Any]) -> dict[str, Any]:
    """Per learner, the log-log slope of memory against world size (1: linear)."""
    from relrl.experiments.results import loglog_slope

    out = {}
    for learner, rows in summary["learn"].items():
        pts = [(int(s), r["memory_positions"]) for s, r in rows.items()
               if r["memory_positions"]]
        if len(pts) >= 2:
            out[learner] = {"memory_slope": loglog_slope(*zip(*pts, strict=True)),
                            "memory_ratio": pts[-1][1] / pts[0][1],
                            "size_ratio": pts[-1][0] / pts[0][0]}
    return out
