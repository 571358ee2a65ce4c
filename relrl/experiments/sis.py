"""Experiment 1 of da Silva & Romero (2012, section 5.1): contingency, Q-learning and ETG in
the Social Interactive Simulator, relrl's relational learner tg beside them (and every other
registered learner).

Protocol: a learner interacts with the caregiver; every ``block`` (500) learning time units
learning stops for an evaluation of ``eval_runs`` (20) runs of ``eval_steps`` (500) time
units, greedy and without learning, with the target placed by a pre-established sequence and
the distractor at random. Each run's CGI (Eq. 5) is recorded; Fig. 5 plots their mean and
standard deviation per evaluation point. Fig. 4 counts the eye contacts the robot establishes
in the first 125 opportunities of the interaction. The learner's memory is reported in the
paper's positions.

Held-out places (``train_places``/``eval_places``): while learning, toys appear (and the
caregiver looks) only at the training places (the caregiver's placement weights); evaluation
puts targets (by a balanced sequence) and distractors at the evaluation places, and the CGI is
also reported for the trained and the held-out places apart (``cgi_places`` at each point:
pooled correct shifts over shifts).

One *job* is one learner with one seed; jobs are independent and run in worker processes
(each holds one Prolog engine).

Two settings (docs/experiment1.md): the default is relrl's fixed task — the simulator's
caregiver, which attends at most once per eye-contact opportunity, and the learners'
defaults; it is the benchmark's task. ``preset="paper-2012"`` (:data:`PRESETS`) is the
paper's 2012 protocol as relrl reads it: the caregiver attends in every time unit of mutual
gaze, the evaluation gives one look per trial, and the contingency learner's fitness is an
execution probability.
"""

from __future__ import annotations

import platform
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from relrl.experiments.protocol import codes_met
from relrl.experiments.results import aggregate, write_outputs
from relrl.experiments.runner import raise_kept, run_jobs
from relrl.learners import DOMAINS, learners
from relrl.machine import machine_info
from relrl.resources import example

__all__ = ["CLAIMS", "DEFAULT_DOMAIN", "PAPER", "PRESETS", "SISConfig", "claims_table",
           "job_from_curve", "paper_claims", "run_job", "run_sis"]

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


#: Named settings of the whole experiment: what each sets (recorded in results.json under
#: ``config``) and why. The reasons are argued, with the paper's words, in docs/engine.md
#: (the contingency learner) and docs/experiment1.md (the caregiver and the protocol).
PRESETS: dict[str, dict[str, Any]] = {
    "paper-2012": {
        "doc": "the paper's 2012 protocol: attention in every time unit of mutual gaze, one "
               "look per evaluation trial, the contingency learner's fitness an execution "
               "probability",
        "caregiver": "paper_2012",
        "caregiver_params": {},
        # "the human initially kept the focus on the robot until it establishes eye
        # contact"; "Once the robot turns its head to any direction, the simulator verifies
        # ... This procedure takes 1 time unit. Afterward, the objects are then removed".
        "eval_caregiver_params": {"contact_timeout": None, "single_look": True},
        # "updating the execution probability of existing ones": fitness is at most 1.
        # Q-learning and ETG: alpha 0.2, gamma 0.9, epsilon 0.05 and rewards +10 / -1 are
        # the paper's values and already the learners' defaults.
        "learner_params": {"contingency": {"max_fitness": 1.0}},
    },
}


#: The paper's three claims about Experiment 1 (section 5.1, Figs. 4 and 5) as checks on a
#: results summary: what the paper says, and the criterion relrl holds a run to.
CLAIMS: dict[str, dict[str, str]] = {
    "after_first_run": {
        "paper": "After the first run, all algorithms improve the robot knowledge attaining "
                 "near of 80% of maximum CGI value",
        "criterion": "every learner's CGI after run 1 within 0.65-0.95"},
    "later": {
        "paper": "the contingency learning do not get to improve its knowledge until the end "
                 "... ETG and Q-learning algorithms improve their learning",
        "criterion": "contingency's final CGI within 0.1 of its run-1 value; ETG's and "
                     "Q-learning's final CGI at least their run-1 value + 0.05"},
    "eye_contacts": {
        "paper": "the contingency learning algorithm established a greater number of eye "
                 "contact than others ... the Q-Learning established a lower number",
        "criterion": "eye contacts in the first 125 opportunities, mean over seeds: "
                     "contingency > ETG > Q-learning"},
}

_PAPERS_THREE = ("contingency", "etg", "qlearning")


def paper_claims(summary: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Check the paper's three claims (:data:`CLAIMS`) on an aggregated summary.

    Returns, per claim, the paper's words, the criterion, the figures it was judged on and
    ``held`` (True or False; None when the run lacks one of the paper's three learners or an
    evaluation point after learning).
    """
    have = all(name in summary and summary[name]["cgi_after_first_run"] is not None
               for name in _PAPERS_THREE)
    first = {n: summary[n]["cgi_after_first_run"] for n in _PAPERS_THREE if n in summary}
    final = {n: summary[n]["cgi_final"] for n in _PAPERS_THREE if n in summary}
    eyes = {n: summary[n]["eye_contacts"]["mean"] for n in _PAPERS_THREE if n in summary}
    held: dict[str, bool | None] = dict.fromkeys(CLAIMS)
    if have:
        held["after_first_run"] = all(0.65 <= first[n] <= 0.95 for n in _PAPERS_THREE)
        held["later"] = (abs(final["contingency"] - first["contingency"]) <= 0.1
                         and all(final[n] >= first[n] + 0.05 for n in ("etg", "qlearning")))
        held["eye_contacts"] = eyes["contingency"] > eyes["etg"] > eyes["qlearning"]
    values = {"after_first_run": {"cgi_after_first_run": first},
              "later": {"cgi_after_first_run": first, "cgi_final": final},
              "eye_contacts": {"eye_contacts_mean": eyes}}
    return {k: {**CLAIMS[k], "held": held[k], "values": values[k]} for k in CLAIMS}


def claims_table(claims: dict[str, dict[str, Any]]) -> str:
    """The claims' verdicts as a few lines of text."""
    lines = []
    for key, c in claims.items():
        verdict = {True: "held", False: "not held", None: "not judged"}[c["held"]]
        figures = "; ".join(
            f"{what.replace('_', ' ')} " + ", ".join(f"{n} {v:.2f}" for n, v in sorted(d.items()))
            for what, d in c["values"].items())
        lines.append(f"{key:<16} {verdict:<10} {figures}")
    return "\n".join(lines)


@dataclass
class SISConfig:
    """Everything that determines an Experiment 1 run (written into results.json)."""

    #: the registered learners (the paper's three, and relrl's own when registered).
    learners: list[str] = field(default_factory=lambda: list(learners(DOMAINS)))
    seeds: list[int] = field(default_factory=lambda: [0])
    points: int = 20                 #: evaluation points after the first (point 0: no learning)
    block: int = 500                 #: learning time units between evaluations
    eval_runs: int = 20
    eval_steps: int = 500
    opportunities: int = 125         #: Fig. 4: eye contacts in the first N opportunities
    caregiver: str = "paper"
    #: overrides of the caregiver's parameters; the defaults are the simulator's (the same
    #: task and reward as ``relrl/SharedAttention-v0``).
    caregiver_params: dict[str, Any] = field(default_factory=dict)
    learner_params: dict[str, dict[str, float]] = field(default_factory=dict)
    domain: str = str(DEFAULT_DOMAIN)
    #: "behaviour": evaluate the robot as it behaves (its exploration kept, no learning);
    #: "greedy": the learners' greedy policy (contingency's roulette stays a roulette).
    eval_policy: str = "behaviour"
    #: seconds one control step may run before the run stops (a rule that never ends); the
    #: robot's own default is 10 s, batch runs on a loaded machine need more room.
    timeout: float = 60.0
    #: toy places used while learning (None: the caregiver's own placement).
    train_places: list[str] | None = None
    #: toy places of the evaluation's targets and distractors (None: all of them).
    eval_places: list[str] | None = None
    #: overrides of the caregiver's parameters while evaluating only (on top of
    #: ``caregiver_params``).
    eval_caregiver_params: dict[str, Any] = field(default_factory=dict)
    #: the named setting this configuration started from (:data:`PRESETS`), or None for
    #: relrl's fixed task.
    preset: str | None = None

    @classmethod
    def from_preset(cls, name: str | None, **fields: Any) -> SISConfig:
        """A configuration with a preset's settings (``None``: the fixed task), then
        ``fields``. Learner parameters are kept for the configuration's learners only.

        Raises:
            ConfigError: unknown preset (the message suggests the closest).
        """
        config = cls(**fields)
        if name is None:
            return config
        if name not in PRESETS:
            from relrl.errors import ConfigError
            from relrl.sim.errors import did_you_mean

            raise ConfigError(f"unknown preset {name!r}{did_you_mean(str(name), PRESETS)} "
                              f"(presets: {', '.join(PRESETS)})")
        preset = PRESETS[name]
        config.preset = name
        config.caregiver = preset["caregiver"]
        config.caregiver_params = {**preset["caregiver_params"], **config.caregiver_params}
        config.eval_caregiver_params = {**preset["eval_caregiver_params"],
                                        **config.eval_caregiver_params}
        for learner, params in preset["learner_params"].items():
            if learner in config.learners:
                config.learner_params[learner] = {**params,
                                                  **config.learner_params.get(learner, {})}
        return config

    def setting(self) -> str:
        """One line saying which setting this is (the preset's or the fixed task's)."""
        if self.preset is not None:
            return f"preset {self.preset}: {PRESETS[self.preset]['doc']}"
        return ("the fixed task (relrl's default and the benchmark's): the caregiver attends "
                "at most once per eye-contact opportunity")

    def jobs(self) -> list[tuple[str, int]]:
        """Every (learner, seed) pair, learners first."""
        return [(learner, seed) for learner in self.learners for seed in self.seeds]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form, with the caregiver's full parameters resolved."""
        from relrl.sim.caregiver import make_caregiver

        out = asdict(self)
        out["caregiver_resolved"] = make_caregiver(self.caregiver,
                                                   self.caregiver_params).params.to_dict()
        if self.eval_caregiver_params:
            out["eval_caregiver_resolved"] = make_caregiver(
                self.caregiver, {**self.caregiver_params, **self.eval_caregiver_params}
            ).params.to_dict()
        out["setting"] = self.setting()
        return out

    def place_split(self) -> tuple[dict[str, Any], dict[str, Any], tuple[str, ...] | None,
                                   dict[str, set[str]]]:
        """Learning and evaluation caregiver overrides, the evaluation's target places and
        the place groups reported apart (empty without held-out places)."""
        from relrl.sim.places import TOY_PLACES

        learn = dict(self.caregiver_params)
        evaluation = {**self.caregiver_params, **self.eval_caregiver_params}
        if self.train_places:
            learn["placement"] = {p: 1.0 for p in self.train_places}
        if not (self.train_places or self.eval_places):
            return learn, evaluation, None, {}
        places = tuple(self.eval_places or TOY_PLACES)
        evaluation["placement"] = {p: 1.0 for p in places}
        trained = set(self.train_places or TOY_PLACES)
        return learn, evaluation, places, {"trained": set(places) & trained,
                                           "held_out": set(places) - trained}


def run_job(config: SISConfig, learner_name: str, seed: int,
            runs: tuple[int, int] | None = None, *,
            report: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """Run one learner with one seed through the whole protocol.

    Evaluations never change the learner (:class:`~relrl.experiments.protocol.Session`):
    learning never depends on how much evaluating was done, and evaluation run *k* gives
    the same numbers whichever process computes it. ``runs=(start, stop)`` computes only
    those evaluation runs (the runner splits a job's evaluation over worker processes; each
    part repeats the short learning phase).

    ``report`` receives one ``{"kind": "point", ...}`` event per evaluation point, holding
    that point's curve entry (a run stopped part-way keeps the points it finished).

    Returns a JSON-ready dict: the CGI (relrl's and literal) of every evaluation run at every
    point, the eye contacts of the first opportunities, the learner's memory, the states
    met. Wall-clock figures go under ``"timing"`` (kept out of results.json so that the
    same seed gives the same file).
    """
    from relrl.experiments.protocol import Session, point_summary
    from relrl.sim.caregiver import evaluation_sequence

    start, stop = runs if runs is not None else (0, config.eval_runs)
    learn, evaluation, places, groups = config.place_split()
    sequence = evaluation_sequence(places) if places else None
    with Session(config.domain, learner_name, config.learner_params.get(learner_name, {}),
                 seed, caregiver=config.caregiver, caregiver_params=learn,
                 eval_caregiver_params=evaluation, eval_steps=config.eval_steps,
                 eval_policy=config.eval_policy, timeout=config.timeout) as session:
        curve = []
        for point in range(config.points + 1):
            if point > 0:
                session.learn(config.block)
            ev = session.evaluate(config.eval_runs, which=(start, stop), sequence=sequence,
                                  by_place=bool(groups))
            entry = {"point": point, "learning_steps": point * config.block,
                     "runs": [start, stop], **point_summary(ev),
                     "memory": session.memory(),
                     "eye_contacts": session.eye_contacts(config.opportunities),
                     "learning": session.learning_summary(),
                     "states_met": session.states_met()}
            if groups:
                entry["place_runs"] = {
                    g: [[sum(r["by_place"].get(p, [0, 0])[i] for p in ps) for i in (0, 1)]
                        for r in ev.runs] for g, ps in sorted(groups.items())}
            curve.append(entry)
            if report is not None:
                report({"kind": "point", "learner": learner_name, "seed": seed,
                        "point": point, "entry": entry})
        return {"learner": learner_name, "seed": seed,
                "params": session.learner.params, "curve": curve, "runs": [start, stop],
                "eval_states": sorted(session.eval_states), "timing": session.timing()}


def _pooled(runs: list[list[int]]) -> dict[str, Any]:
    """The runs' ``[correct, shifts]`` and their pooled CGI (None: no shift at all)."""
    correct, shifts = sum(r[0] for r in runs), sum(r[1] for r in runs)
    return {"cgi": correct / shifts if shifts else None, "runs": runs}


def job_from_curve(learner: str, seed: int, parts: list[list[dict[str, Any]]],
                   params: dict[str, float] | None = None,
                   eval_states: set[int] | None = None) -> dict[str, Any] | None:
    """One (learner, seed) job from the curves its parts computed (possibly unfinished).

    The learning phase is the same in every part (it never depends on the evaluation), so
    the learning figures come from any part that reached a point, and the evaluation runs
    are concatenated in order. A run stopped part-way keeps every evaluation run that
    finished: a point some part did not reach is kept with the runs it has and marked
    ``"incomplete": true``. ``None`` when no part finished a point.
    """
    expected = len(parts)
    parts = sorted((c for c in parts if c), key=lambda c: c[0]["runs"][0])
    if not parts:
        return None
    common = min(len(c) for c in parts)
    longest = max(parts, key=len)
    for c in parts:
        for key in ("memory", "eye_contacts", "learning"):
            if common and c[common - 1][key] != parts[0][common - 1][key]:
                raise RuntimeError(f"parts of {learner} seed {seed} disagree on {key}: the "
                                   "learning phase is not repeatable")
    curve = []
    for i in range(len(longest)):
        have = [c[i] for c in parts if len(c) > i]
        runs = {k: [v for entry in have for v in entry[k]]
                for k in ("cgi_runs", "cgi_literal_runs", "eye_contacts_runs")}
        curve.append({"point": have[0]["point"], "learning_steps": have[0]["learning_steps"],
                      "cgi_mean": float(np.mean(runs["cgi_runs"])),
                      "cgi_std": float(np.std(runs["cgi_runs"])),
                      "cgi_literal_mean": float(np.mean(runs["cgi_literal_runs"])),
                      "cgi_literal_std": float(np.std(runs["cgi_literal_runs"])),
                      "memory": have[0]["memory"], **runs})
        if len(have) < expected:
            curve[-1]["incomplete"] = True
        if "place_runs" in have[0]:
            curve[-1]["cgi_places"] = {
                g: _pooled([r for entry in have for r in entry["place_runs"][g]])
                for g in have[0]["place_runs"]}
    last = longest[-1]
    job = {"learner": learner, "seed": seed, "curve": curve,
           "eye_contacts": last["eye_contacts"],
           "mutual_gaze_events": last["learning"]["mutual_gaze_events"],
           "learning": last["learning"], "memory": last["memory"],
           "states_met": {"learning": last["states_met"],
                          "evaluation": (codes_met(eval_states) if eval_states is not None
                                         else None)}}
    if params is not None:
        job["params"] = params
    return job


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
