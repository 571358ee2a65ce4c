"""Where each number of a session comes from: the devices or the simulator.

A session on a camera and/or a head learns from the devices, but its evaluations (Fig. 6)
and naming executions (Table 1) run on the scripted world -- a caregiver on the real devices
cannot be replayed a hundred times. :func:`provenance` says so for the console, the summary
(``summary["where"]``), the plots and the recorded ``session.json``.
"""

from __future__ import annotations

import time
from typing import Any

__all__ = ["provenance", "session_manifest"]

SIMULATED = " (SIMULATED on the scripted world, not on the devices)"


def provenance(opts: Any) -> dict[str, Any]:
    """Where learning, metrics, evaluations and naming happen, with console labels.

    Args:
        opts: the session's :class:`~relrl.episodes.session.RunOptions`.
    """
    camera, head = opts.camera, opts.head
    # the simulated head moves nothing real: a session with it alone is all simulation
    on_devices = camera is not None or (head is not None and head != "sim")
    devices = ", ".join(x for x in (f"camera {camera}" if camera is not None else "",
                                    f"head {head}" if head is not None else "") if x)
    where: dict[str, Any] = {
        "learning": f"devices ({devices})" if on_devices else "simulator",
        "metrics": ("estimated: the caregiver's gaze from the head pose perception reports"
                    if camera is not None else "the simulator's ground truth"),
        "evaluation": "simulator" + (" (not the devices)" if on_devices else ""),
        "naming": "simulator" + (" (not the devices)" if on_devices else ""),
        "evaluation_label": SIMULATED if on_devices else "",
        "naming_label": SIMULATED if on_devices else "",
        "simulated_evaluation": on_devices,
    }
    return where


def session_manifest(run: Any, opts: Any, summary: dict[str, Any], timing: dict[str, Any],
                     recorded: dict[str, Any]) -> dict[str, Any]:
    """The ``session.json`` of a recorded session: what was run, on what, and what is where."""
    from relrl import __version__
    from relrl.terms import format_term

    ep = run.episode
    files = {"trace": "trace.jsonl", "summary": "summary.json", "timing": "timing.json",
             **getattr(run.tap, "files", {})}
    if "policy" in summary:
        files["policy"] = summary["policy"]
    return {
        "relrl": __version__, "recorded": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "episode": ep.name, "seed": ep.seed, "steps": summary["steps"],
        "learner": {"name": ep.learner, "params": run.learner.params},
        "necessities": run.agent.necessities,
        "responses": [format_term(r) for r in run.agent.responses],
        "perception": ep.perception, "devices": {"camera": opts.camera, "head": opts.head},
        "where": summary.get("where"), "recording": recorded, "seconds": timing["seconds"],
        "files": files,
    }

