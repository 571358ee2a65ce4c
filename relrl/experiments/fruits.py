"""Experiment 2 of da Silva & Romero (2012, section 5.2): gaze following with fruits, then
declarative pointing (naming the fruit), on the episode world.

The protocol is an episode script (``examples/episodes/experiment2.toml``, run by
``relrl run``); this module holds its two measurements:

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

__all__ = ["OUTCOMES", "PAPER", "Naming", "evaluate_cgi", "naming_execution", "rates"]

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
                 "learning_steps": 100, "without_objects": 30, "eval_runs": 5,
                 "eval_steps": 100, "executions": 5},
}


class Naming:
    """Declarative pointing: an ART2 :class:`perception.FruitNamer` fed by the episode.

    Every word of the vocabulary heard while a coloured object is in view teaches the namer
    (one Table 1 outcome per such presentation); :meth:`point` gives the sentence the robot
    says when it names the object in view.

    Args:
        vocabulary: the caregiver's words for the fruits.
        confident_after: hearings before a category's name is confident.
    """

    def __init__(self, vocabulary: set[str], confident_after: int = 3) -> None:
        from perception import FruitNamer

        self.vocabulary = vocabulary
        self.namer = FruitNamer(confident_after=confident_after)
        self.outcomes: list[str] = []

    def hear(self, words: list[str], features: np.ndarray | None) -> str | None:
        """Words heard with the object's colour features in view; returns the outcome."""
        if features is None:
            return None
        for word in words:
            if word in self.vocabulary:
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


def _zero_nan(x: float) -> float:
    return 0.0 if math.isnan(x) else float(x)


def evaluate_cgi(agent: Any, episode: Any, seeds: list[int],
                 stop: Callable[[], bool] = lambda: False) -> dict[str, Any]:
    """Evaluate gaze following: one greedy run without learning per seed; CGI per run.

    A stop request ends the evaluation at once; only the runs that finished are counted
    (fewer ``cgi_runs`` than seeds tell the caller the point was cut short)."""
    from relrl.episodes.world import EpisodeWorld
    from relrl.loop import Interaction
    from relrl.sim.metrics import GazeMetrics

    steps = episode.evaluation["steps"]
    env = EpisodeWorld(episode, protocol_only=True, sequence=True, max_steps=steps)
    values, contacts = [], []
    for seed in seeds:
        if stop():
            break
        metrics = GazeMetrics(hold=episode.caregiver.get("contact_hold", 3))
        run = Interaction(env, agent, on_step=lambda r, m=metrics: m.add(r.info["record"]))
        run.reset(seed=int(seed))
        for _ in range(steps):
            if stop():
                break
            run.run(1, learning=False, keep=False)
        else:
            values.append(_zero_nan(metrics.cgi().value))
            contacts.append(metrics.eye_contacts().established)
            continue
        break  # a run cut short by a stop request is not counted
    agent.end_episode()
    return {"cgi_mean": float(np.mean(values)) if values else 0.0,
            "cgi_std": float(np.std(values)) if values else 0.0,
            "cgi_runs": values, "eye_contacts": contacts}


def naming_execution(agent: Any, episode: Any, seed: int, *, learning: bool = False,
                     on_step: Callable[[Any, str | None], None] | None = None,
                     stop: Callable[[], bool] = lambda: False) -> dict[str, Any]:
    """One declarative-pointing execution with a fresh namer; stops after ``presentations``
    taught presentations or ``max_steps`` time units."""
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
            "counts": counts, "said": said[:20], "categories": naming.namer.net.categories}


def rates(executions: list[dict[str, Any]]) -> dict[str, list[float]]:
    """Per outcome, ``[mean, sd]`` in percent of each execution's presentations."""
    out = {}
    for k in OUTCOMES:
        r = [100.0 * e["counts"][k] / e["presentations"] for e in executions
             if e["presentations"]]
        out[k] = [round(float(np.mean(r)), 2), round(float(np.std(r)), 2)] if r else [0.0, 0.0]
    return out
