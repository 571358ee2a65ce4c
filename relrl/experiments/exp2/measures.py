"""Experiment 2's two measurements (da Silva & Romero 2012, section 5.2).

The protocol is an episode script (``examples/episodes/experiment2.toml``, run by
``relrl run``); this module holds what it measures:

* :func:`evaluate_cgi` -- learning is interrupted and the robot is evaluated by ``runs`` runs
  of ``steps`` time units, greedy and without learning, the fruit placed by a pre-established
  cycle; the CGI (Eq. 5) of each run, their mean and standard deviation (Fig. 6).
* :func:`naming_execution` -- one execution of the declarative-pointing session: a fresh ART2
  :class:`perception.FruitNamer`, the caregiver shows fruits and says their names when the
  robot looks at them with her, the robot names them from their colour; the outcome counts
  of Table 1. :func:`rates` turns several executions into mean and standard deviation (%).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["OUTCOMES", "PAPER", "Naming", "evaluate_cgi", "merge_confusions",
           "naming_execution", "rates", "report_lines", "table1", "unit_bound"]

#: Table 1 outcomes, in the paper's order of the table.
OUTCOMES: tuple[str, ...] = ("unknown", "correct_guess", "incorrect_guess", "error", "success")

#: What the paper reports for Experiment 2 (Table 1: mean +- sd in %, five executions).
PAPER: dict[str, Any] = {
    "table1": {"unknown": [7.23, 0.58], "correct_guess": [17.47, 1.28],
               "incorrect_guess": [1.8, 0.44], "error": [0.6, 0.2], "success": [72.89, 2.19]},
    "fig6": "mean CGI of 5 runs x 100 time units rises fast until the second evaluation, then "
            "slowly to a plateau (no numbers given)",
    "settings": {"alpha": 0.2, "gamma": 0.9, "epsilon": 0.05, "threshold": 0.5, "delta": 0.2,
                 "bias": 1.0, "recurrent": 1.0,
                 "weights": {"hear(attention)": 1.5, "see(frontal(face))": 0.95,
                             "see(looking_frontal(face))": 0.5,
                             "see(looking_fruit(object))": 1.5},
                 "learning_units": 100, "without_objects": 30, "eval_runs": 5,
                 "eval_units": 100, "executions": 5,
                 "time_unit": "\"time units or runs\" (our reading: an interaction cycle)"},
}


class Naming:
    """Declarative pointing: an ART2 :class:`perception.FruitNamer` fed by the episode.

    Every word of the vocabulary heard while a coloured object is in view teaches the namer
    (one Table 1 outcome per such presentation); :meth:`point` gives the sentence the robot
    says when it names the object in view. The caregiver always says the right word, so what
    the robot would have said before hearing it, against that word, is the confusion table.

    Args:
        vocabulary: the caregiver's words for the fruits.
        confident_after: hearings before a category's name is confident.
    """

    def __init__(self, vocabulary: set[str], confident_after: int = 3) -> None:
        from perception import FruitNamer

        self.vocabulary = vocabulary
        self.namer = FruitNamer(confident_after=confident_after)
        self.outcomes: list[str] = []
        #: (word heard, name the robot would have said or None) per taught presentation.
        self.said: list[tuple[str, str | None]] = []
        #: words of the vocabulary heard while perception saw no coloured object.
        self.missed = 0

    def hear(self, words: list[str], features: np.ndarray | None) -> str | None:
        """Words heard with the object's colour features in view; returns the outcome."""
        for word in words:
            if word in self.vocabulary:
                if features is None:
                    self.missed += 1
                    return None
                self.said.append((word, self.namer.name(features)[0]))
                outcome = self.namer.teach(features, word)
                self.outcomes.append(outcome)
                return outcome
        return None

    def point(self, features: np.ndarray | None) -> str:
        """What the robot says when it points at the object with these features."""
        from relrl.speech import sentence_for

        if features is None:
            return "what is this?"
        name, confident = self.namer.name(features)
        return sentence_for(name, confident)

    def counts(self) -> dict[str, int]:
        """Outcome counts (every outcome present)."""
        return {k: self.outcomes.count(k) for k in OUTCOMES}

    def confusion(self) -> dict[str, dict[str, int]]:
        """Per word heard (the fruit shown), how often the robot would have said each name
        (``"nothing"``: it had no name for it)."""
        from perception.fruits import confusion_table

        return confusion_table(self.said)


def merge_confusions(tables: list[dict[str, dict[str, int]]]) -> dict[str, dict[str, int]]:
    """The sum of several confusion tables."""
    out: dict[str, dict[str, int]] = {}
    for table in tables:
        for shown, row in table.items():
            merged = out.setdefault(shown, {})
            for name, n in row.items():
                merged[name] = merged.get(name, 0) + n
    return {k: dict(sorted(v.items())) for k, v in sorted(out.items())}


def _zero_nan(x: float) -> float:
    return 0.0 if math.isnan(x) else float(x)


def unit_bound(episode: Any) -> int:
    """The most control steps one interaction cycle of the protocol caregiver can take."""
    p = episode.caregiver
    return p["contact_timeout"] + p["latency"] + p["timeout"] + p["joint"] + p["contact_hold"] + 2


def evaluate_cgi(agent: Any, episode: Any, seeds: list[int],
                 stop: Callable[[], bool] = lambda: False,
                 on_run: Callable[[int], None] | None = None) -> dict[str, Any]:
    """Evaluate gaze following: one run of ``evaluation.steps`` time units per seed, without
    learning, fruits placed by the pre-established cycle and only the robot's first turn of
    each presentation checked; the CGI (Eq. 5) of each run.

    The learner is left exactly as it was (:meth:`relrl.loop.Agent.preserved`: working memory,
    necessity units, the last step, every random stream), and each run draws from streams
    seeded for that run alone, so learning never depends on how often it is evaluated.
    ``evaluation.policy`` is ``behaviour`` (the robot as it behaves, exploration kept, as in
    Experiment 1) or ``greedy``. A run in which the robot never turned from the caregiver's
    face to follow her gaze has no CGI; it counts as 0 and is counted in ``no_shift_runs``.

    A stop request ends the evaluation at once; only the runs that finished are counted
    (fewer ``cgi_runs`` than seeds tell the caller the point was cut short). ``on_run(k)``
    is called before run ``k`` (from 0) starts: the session's monitor says which run is on.
    """
    from relrl.episodes.world import EpisodeWorld
    from relrl.loop import Interaction
    from relrl.sim.metrics import GazeMetrics

    ev = episode.evaluation
    units = ev["steps"]
    explore = ev.get("policy", "behaviour") == "behaviour"
    env = EpisodeWorld(episode, protocol_only=True, sequence=True, first_shift=True)
    limit = units * (1 if episode.time_unit == "step" else unit_bound(episode))
    values, contacts, shifts, no_shift, steps = [], [], [], 0, 0
    states, done = set(agent.states), agent.steps
    with agent.preserved():
        for k, seed in enumerate(seeds):
            if stop():
                break
            if on_run is not None:
                on_run(k)
            agent.reseed(int(seed))
            metrics = GazeMetrics(hold=episode.caregiver.get("contact_hold", 3))
            run = Interaction(env, agent, on_step=lambda r, m=metrics: m.add(r.info["record"]))
            run.reset(seed=int(seed))
            n = 0
            while env.units_done < units and n < limit and not stop():
                run.run(1, learning=False, explore=explore, keep=False)
                n += 1
            steps += n
            if stop():
                break  # a run cut short by a stop request is not counted
            c = metrics.cgi()
            no_shift += c.shifts == 0
            values.append(_zero_nan(c.value))
            shifts.append(c.shifts)
            contacts.append(metrics.eye_contacts().established)
    agent.states, agent.steps = states, done
    return {"cgi_mean": float(np.mean(values)) if values else 0.0,
            "cgi_std": float(np.std(values)) if values else 0.0,
            "cgi_runs": values, "shifts": shifts, "no_shift_runs": int(no_shift),
            "eye_contacts": contacts, "control_steps": steps}


def naming_execution(agent: Any, episode: Any, seed: int, *, learning: bool = True,
                     on_step: Callable[[Any, str | None], None] | None = None,
                     stop: Callable[[], bool] = lambda: False) -> dict[str, Any]:
    """One declarative-pointing execution (a guided learning session: the robot keeps
    learning) with a fresh namer; stops after ``presentations`` taught presentations or
    ``max_steps`` control steps."""
    from relrl.episodes.world import EpisodeWorld
    from relrl.loop import Interaction

    cfg = episode.naming
    naming = Naming({episode.word_for(k) for k in episode.fruits}, cfg["confident_after"])
    env = EpisodeWorld(episode, protocol_only=True, sequence=False)
    said: list[str] = []
    run = Interaction(env, agent)
    info = run.reset(seed=seed)
    steps = 0
    while len(naming.outcomes) < cfg["presentations"] and steps < cfg["max_steps"]:
        if stop():
            break
        in_view = info["features"]
        (record,) = run.run(1, learning=learning, keep=True)
        if record.out.action == "name_object":
            said.append(naming.point(in_view))
        outcome = naming.hear(record.info["words"], record.info["features"])
        if on_step is not None:
            on_step(record, outcome)
        info = record.info
        steps += 1
    agent.end_episode()
    counts = naming.counts()
    return {"seed": seed, "steps": steps, "presentations": len(naming.outcomes),
            "missed": naming.missed, "counts": counts, "confusion": naming.confusion(),
            "said": said[:20], "categories": naming.namer.net.categories}


def rates(executions: list[dict[str, Any]]) -> dict[str, list[float]] | None:
    """Per outcome, ``[mean, sd]`` in percent of each execution's presentations, over the
    executions that had any; ``None`` when none had (there is no rate to give)."""
    used = [e for e in executions if e["presentations"]]
    if not used:
        return None
    out = {}
    for k in OUTCOMES:
        r = [100.0 * e["counts"][k] / e["presentations"] for e in used]
        out[k] = [round(float(np.mean(r)), 2), round(float(np.std(r)), 2)]
    return out


def table1(executions: list[dict[str, Any]]) -> dict[str, Any]:
    """Table 1 of a run: the executions, their rates (``None`` and a note when no
    presentation happened), the confusions summed over executions, the paper's values."""
    complete = [e for e in executions if not e.get("interrupted")]  # a stopped one is kept
    empty = sum(1 for e in complete if not e["presentations"])
    out: dict[str, Any] = {"executions": executions, "rates": rates(complete),
                           "executions_without_presentation": empty,
                           "confusion": merge_confusions([e.get("confusion", {})
                                                          for e in complete]),
                           "paper": PAPER["table1"]}
    if empty:
        out["note"] = (f"{empty} of {len(complete)} executions had no naming presentation "
                       "(the robot never looked at a fruit with the caregiver); rates are over "
                       "the others" if empty < len(complete) else
                       "no naming presentation happened in any execution: no rates")
    return out


def report_lines(summary: dict[str, Any]) -> list[str]:
    """The evaluation curve, Table 1 and the confusions of a run's summary, as text lines."""
    lines = []
    unit = summary.get("time_unit", "step")
    sim = " (simulated)" if summary.get("where", {}).get("simulated_evaluation") else ""
    if sim and (summary.get("evaluation") or "table1" in summary):
        lines.append("  evaluations and naming below ran on the scripted world (simulated), "
                     "not on the devices")
    for p in summary.get("evaluation", []):
        lines.append(f"  evaluation{sim} after {p['units']:4d} {unit}s: CGI {p['cgi_mean']:.3f} +- "
                     f"{p['cgi_std']:.3f}" + (f"  ({p['no_shift_runs']} runs without a shift)"
                                              if p.get("no_shift_runs") else ""))
    t1 = summary.get("table1")
    if t1:
        if t1.get("note"):
            lines.append(f"  Table 1: {t1['note']}")
        if t1["rates"] is not None:
            n = [e["presentations"] for e in t1["executions"]]
            lines.append(f"  Table 1{sim} (mean +- sd % over {len(n)} executions of {min(n)}-"
                         f"{max(n)} presentations; measured | paper):")
            for k, (m, sd) in t1["rates"].items():
                pm, psd = t1["paper"][k]
                lines.append(f"    {k:16s} {m:6.2f} +- {sd:5.2f} | {pm:6.2f} +- {psd:.2f}")
        if t1.get("confusion"):
            lines.append("  confusions (fruit shown: what the robot would have said):")
            for shown, row in t1["confusion"].items():
                total = sum(row.values())
                cells = ", ".join(f"{k} {v} ({100.0 * v / total:.1f} %)" for k, v in row.items())
                lines.append(f"    {shown:8s} {cells}")
    return lines
