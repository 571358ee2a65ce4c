"""Greedy episodes of a world as a session folder that ``relrl replay`` shows.

Each step of each kept episode becomes one trace line in the monitor's own shape
(:class:`relrl.monitor.view.StepView`): the world's state as the percepts, the action as the
response, the reward, and the episode (size, goal, its step and the optimum) as the phase.
The page then steps through a world's states as it steps through a robot's percepts.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from relrl.monitor.view import StepView
from relrl.outdir import write_atomic, write_json_atomic

__all__ = ["step_rows", "write_replay"]


def step_rows(ep: dict[str, Any], *, world: str, size: int, label: str,
              t0: int = 0) -> list[dict[str, Any]]:
    """One traced episode (as :func:`relrl.worlds.learn.learn_task` keeps it: ``goal``,
    ``steps``, ``optimal``, ``trace``) as the monitor's rows (:meth:`StepView.row`), numbered
    from ``t0 + 1``: the world's state as the percepts, the action as the response, the
    episode (size, ``label``, goal, step, optimum) as the phase."""
    rows = []
    for i, step in enumerate(ep["trace"]):
        phase = (f"size {size} · {label} · goal {ep['goal']} · step {i} of {ep['steps']} "
                 f"(optimal {ep['optimal']})")
        rows.append(StepView(
            t=t0 + i + 1, phase=phase, percepts=list(step["state"]), memory=None,
            memory_size=None, state=0, necessity=None, activation={},
            reward=float(step["reward"] or 0), response=step["action"], allowed=[],
            metrics={}, extra={"world": world, "size": size}).row())
    return rows


def write_replay(folder: Path, traces: dict[str, list[dict[str, Any]]], *, learner: str,
                 world: str, task: str, seed: int,
                 graph: dict[str, Any] | None = None) -> list[Path]:
    """Write ``trace.jsonl``, ``session.json`` and (with ``graph``) ``trees.jsonl`` of the
    kept episodes into ``folder``.

    Args:
        folder: the session folder, inside a claimed output folder (made when missing).
        traces: per size, episodes as :func:`relrl.worlds.learn.learn_task` keeps them.
        learner, world, task, seed: for the page's heading.
        graph: the learned tree (:meth:`relrl.engine.Engine.graph`), shown from the start.
    """
    rows: list[dict[str, Any]] = []
    for size, episodes in traces.items():
        for n, ep in enumerate(episodes, 1):
            rows += step_rows(ep, world=world, size=int(size), label=f"episode {n}",
                              t0=len(rows))
    files = [write_atomic(folder / "trace.jsonl",
                          "".join(json.dumps(r) + "\n" for r in rows)),
             write_json_atomic(folder / "session.json",
                               {"episode": f"{world}: {task}", "learner": {"name": learner},
                                "seed": seed, "necessities": [], "responses": None})]
    if graph and graph.get("nodes"):
        files.append(write_atomic(folder / "trees.jsonl",
                                  json.dumps({"t": 1, "graph": graph}) + "\n"))
    return files
