"""Experiment 1 of da Silva & Romero (2012, section 5.1): contingency, Q-learning and ETG in
the Social Interactive Simulator, and relrl's relational learner tg beside them.

Protocol: a learner interacts with the caregiver; every ``block`` (500) learning time units
learning stops for an evaluation of ``eval_runs`` (20) runs of ``eval_steps`` (500) time
units, greedy and without learning, with the target placed by a pre-established sequence and
the distractor at random. Each run's CGI (Eq. 5) is recorded; Fig. 5 plots their mean and
standard deviation per evaluation point. Fig. 4 counts the eye contacts the robot establishes
in the first 125 opportunities of the interaction. The learner's memory is reported in the
paper's positions.

Held-out places (``train_places``/``eval_places``): while learning, toys appear (and the
caregiver looks) only at the training places; evaluation puts targets and distractors at the
evaluation places, and the CGI is also reported for the trained and the held-out places
apart (``cgi_places`` at each point: pooled correct shifts over shifts).

One *job* is one learner with one seed; jobs are independent and run in worker processes
(each holds one Prolog engine).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from relrl.resources import example

__all__ = ["SISConfig", "run_job", "merge_parts", "DEFAULT_DOMAIN", "PAPER"]

#: the SIS domain shipped with relrl (package data).
DEFAULT_DOMAIN = example("domains/sis.pl")

#: What the paper reports for Experiment 1 (section 5.1, Figs. 4 and 5).
PAPER: dict[str, Any] = {
    "cgi_after_first_run": "about 0.8 of the maximum CGI for all three learners",
    "cgi_later": "contingency flat; ETG and Q-learning rise to a plateau",
    "eye_contacts": "contingency most, Q-learning fewest (Fig. 4, first 125 opportunities)",
    "memory_positions": {"qlearning": 3150, "etg": 396,
                         "etg_detail": "68 nodes, 29 leaves, 328 stored actions"},
}


@dataclass
class SISConfig:
    """Everything that determines an Experiment 1 run (written into results.json)."""

    learners: list[str] = field(
        default_factory=lambda: ["contingency", "qlearning", "etg", "tg"])
    seeds: list[int] = field(default_factory=lambda: [0])
    points: int = 20                 #: evaluation points after the first (point 0: no learning)
    block: int = 500                 #: learning time units between evaluations
    eval_runs: int = 20
    eval_steps: int = 500
    opportunities: int = 125         #: Fig. 4: eye contacts in the first N opportunities
    caregiver: str = "paper"
    #: The caregiver attends to the robot in every time unit of mutual gaze (Triesch et al.'s
    #: reward for looking at the face); see docs/experiments.md for why and for the ablation.
    caregiver_params: dict[str, Any] = field(
        default_factory=lambda: {"attention_during_gaze": True})
    learner_params: dict[str, dict[str, float]] = field(default_factory=dict)
    domain: str = str(DEFAULT_DOMAIN)
    #: "behaviour": evaluate the robot as it behaves (its exploration kept, no learning);
    #: "greedy": the learners' greedy policy (contingency's roulette stays a roulette).
    eval_policy: str = "behaviour"
    #: toy places used while learning (None: the caregiver's own placement).
    train_places: list[str] | None = None
    #: toy places of the evaluation's targets and distractors (None: all of them).
    eval_places: list[str] | None = None

    def jobs(self) -> list[tuple[str, int]]:
        """Every (learner, seed) pair, learners first."""
        return [(learner, seed) for learner in self.learners for seed in self.seeds]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return asdict(self)


def _nan_to_zero(x: float) -> float:
    return 0.0 if math.isnan(x) else x


class _PlaceShifts:
    """Shifts from the human (as in the CGI) counted apart for groups of gazed places."""

    def __init__(self, groups: dict[str, set[str]]) -> None:
        self.groups = groups
        self.counts = {g: [0, 0] for g in groups}   # correct, shifts
        self._prev: Any = None

    def add(self, rec: Any) -> None:
        prev = self._prev
        if (prev is not None and prev.focus == "centre" and prev.gaze != "frontal"
                and rec.focus != "centre"):
            for name, places in self.groups.items():
                if prev.gaze in places:
                    self.counts[name][1] += 1
                    self.counts[name][0] += rec.focus == prev.gaze
        self._prev = rec


def _places_cgi(by_places: dict[str, list[list[int]]]) -> dict[str, Any]:
    """Per place group: the runs' [correct, shifts] and the pooled CGI (None: no shift)."""
    out = {}
    for g, runs in by_places.items():
        correct, shifts = sum(r[0] for r in runs), sum(r[1] for r in runs)
        out[g] = {"cgi": correct / shifts if shifts else None, "runs": runs}
    return out


def _caregivers(config: SISConfig) -> tuple[Any, Any, dict[str, set[str]]]:
    """The learning and evaluation caregivers, and the place groups reported apart."""
    from relrl.sim.caregiver import EVALUATION_SEQUENCE, make_caregiver
    from relrl.sim.places import TOY_PLACES

    params = dict(config.caregiver_params)
    if config.train_places:
        params["placement"] = {p: 1.0 for p in config.train_places}
    caregiver = make_caregiver(config.caregiver, params)
    evaluation = caregiver.params.for_evaluation()
    groups: dict[str, set[str]] = {}
    if config.train_places or config.eval_places:
        places = list(config.eval_places or TOY_PLACES)
        sequence = tuple(p for p in EVALUATION_SEQUENCE if p in places)
        evaluation = evaluation.replace(placement={p: 1.0 for p in places},
                                        target_sequence=sequence)
        trained = set(config.train_places or TOY_PLACES)
        groups = {"trained": set(places) & trained, "held_out": set(places) - trained}
    return caregiver, make_caregiver(config.caregiver, evaluation), groups


def run_job(config: SISConfig, learner_name: str, seed: int,
            progress: Callable[[str, int, int], None] | None = None,
            runs: tuple[int, int] | None = None) -> dict[str, Any]:
    """Run one learner with one seed through the whole protocol.

    Each evaluation run draws from random streams seeded for that run alone, and the
    learner's own streams are saved before an evaluation and restored after it: learning
    never depends on how much evaluating was done, and evaluation run *k* gives the same
    numbers whichever process computes it. ``runs=(start, stop)`` computes only those
    evaluation runs (the runner splits a job's evaluation over worker processes; each
    part repeats the short learning phase).

    Returns a JSON-ready dict: the CGI of every evaluation run at every point, the eye
    contacts of the first opportunities, the learner's memory, the states met.
    Wall-clock figures go under ``"timing"`` (kept out of results.json so that the same
    seed gives the same file).
    """
    start, stop = runs if runs is not None else (0, config.eval_runs)
    from relrl.kb import KnowledgeBase, gateway_calls
    from relrl.learners import make_learner
    from relrl.loop import Agent, Interaction
    from relrl.sim.metrics import GazeMetrics
    from relrl.sim.sis import SharedAttentionEnv

    t_start = time.perf_counter()
    calls0 = gateway_calls()
    kb = KnowledgeBase(config.domain)
    try:
        learner = make_learner(learner_name, **config.learner_params.get(learner_name, {}))
        agent = Agent(kb, learner, seed=seed)
        caregiver, eval_caregiver, groups = _caregivers(config)
        train_env = SharedAttentionEnv(caregiver, max_steps=None, record_trace=False)
        eval_env = SharedAttentionEnv(eval_caregiver, max_steps=config.eval_steps,
                                      record_trace=False)
        learning_metrics = GazeMetrics()
        learning = Interaction(train_env, agent,
                               on_step=lambda r: learning_metrics.add(r.info["record"]))
        learning.reset(seed=seed)
        eval_seeds = np.random.SeedSequence([seed, 1]).generate_state(config.eval_runs)
        learning_states: set[int] = set()
        eval_states: set[int] = set()
        steps = 0

        def evaluate() -> tuple[list[float], dict[str, list[list[int]]]]:
            nonlocal steps
            values = []
            by_places: dict[str, list[list[int]]] = {g: [] for g in groups}
            saved = agent.save_random()
            before = set(agent.states)
            agent.states.clear()
            for run_seed in eval_seeds[start:stop]:
                agent.reseed(int(run_seed))
                metrics = GazeMetrics()
                shifts = _PlaceShifts(groups)

                def on_step(r: Any, m: GazeMetrics = metrics, p: _PlaceShifts = shifts) -> None:
                    m.add(r.info["record"])
                    p.add(r.info["record"])

                ev = Interaction(eval_env, agent, on_step=on_step if groups else
                                 lambda r, m=metrics: m.add(r.info["record"]))
                ev.reset(seed=int(run_seed))
                ev.run(config.eval_steps, learning=False,
                       explore=config.eval_policy == "behaviour", keep=False)
                steps += config.eval_steps
                values.append(_nan_to_zero(metrics.cgi().value))
                for g, counts in shifts.counts.items():
                    by_places[g].append(list(counts))
            agent.end_episode()
            agent.restore_random(saved)
            eval_states.update(agent.states)
            agent.states = before
            return values, by_places

        curve = []
        for point in range(config.points + 1):
            if point > 0:
                learning.run(config.block, learning=True, keep=False)
                learning_states |= agent.states
                steps += config.block
            values, by_places = evaluate()
            curve.append({"point": point, "learning_steps": point * config.block,
                          "cgi_mean": float(np.mean(values)), "cgi_std": float(np.std(values)),
                          "cgi_runs": values, "memory": learner.size()})
            if groups:
                curve[-1]["cgi_places"] = _places_cgi(by_places)
            if progress is not None:
                progress(learner_name, seed, point)
        contacts = learning_metrics.eye_contacts(config.opportunities)
        result = {
            "learner": learner_name,
            "seed": seed,
            "params": learner.params,
            "curve": curve,
            "eye_contacts": {"established": contacts.established,
                             "opportunities": contacts.opportunities,
                             "per_opportunity": [bool(f) for f in contacts.per_opportunity]},
            "mutual_gaze_events": learning_metrics.mutual_gaze_events,
            "learning_cgi": _nan_to_zero(learning_metrics.cgi().value),
            "memory": learner.size(),
            "states_met": {"learning": len(learning_states),
                           "all": len(learning_states | eval_states)},
            "runs": [start, stop],
            "eval_states": sorted(eval_states),
        }
        elapsed = time.perf_counter() - t_start
        calls = gateway_calls() - calls0
        result["timing"] = {"seconds": elapsed, "steps": steps,
                            "steps_per_second": steps / elapsed if elapsed else 0.0,
                            "gateway_calls_per_step": calls / steps if steps else 0.0}
        return result
    finally:
        kb.close()


def merge_parts(parts: list[dict[str, Any]]) -> dict[str, Any]:
    """Join the parts of one (learner, seed) job computed by different processes.

    The learning phase is the same in every part (it never depends on the evaluation);
    the evaluation runs are concatenated in order.
    """
    parts = sorted(parts, key=lambda p: p["runs"][0])
    first = parts[0]
    for p in parts[1:]:
        for key in ("eye_contacts", "memory", "mutual_gaze_events", "learning_cgi"):
            if p[key] != first[key]:
                raise RuntimeError(f"parts of {first['learner']} seed {first['seed']} disagree "
                                   f"on {key}: the learning phase is not repeatable")
    job = {k: v for k, v in first.items() if k not in ("runs", "eval_states", "timing")}
    job["curve"] = []
    for i, point in enumerate(first["curve"]):
        runs = [v for p in parts for v in p["curve"][i]["cgi_runs"]]
        job["curve"].append({"point": point["point"], "learning_steps": point["learning_steps"],
                             "cgi_mean": float(np.mean(runs)), "cgi_std": float(np.std(runs)),
                             "cgi_runs": runs, "memory": point["memory"]})
        if "cgi_places" in point:
            job["curve"][-1]["cgi_places"] = _places_cgi(
                {g: [r for p in parts for r in p["curve"][i]["cgi_places"][g]["runs"]]
                 for g in point["cgi_places"]})
    learning_states = first["states_met"]["learning"]
    eval_states = set().union(*(p["eval_states"] for p in parts))
    job["states_met"] = {"learning": learning_states, "evaluation": len(eval_states)}
    job["timing"] = {
        "seconds": sum(p["timing"]["seconds"] for p in parts),
        "steps": sum(p["timing"]["steps"] for p in parts),
        "parts": len(parts),
    }
    job["timing"]["steps_per_second"] = job["timing"]["steps"] / job["timing"]["seconds"]
    job["timing"]["gateway_calls_per_step"] = float(np.mean(
        [p["timing"]["gateway_calls_per_step"] for p in parts]))
    return job
