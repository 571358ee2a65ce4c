"""The live monitor on any control loop (the simulator, an experiment, a script of yours)::

    tap = LoopTap(hub, agent)
    interaction = Interaction(env, agent, on_step=tap)
    for _ in range(steps):
        interaction.run(1, keep=False, want=tap.want())

Every step hands the necessity outputs and reward to the hub's plot; at the hub's rate the
step is asked (``want``) for working memory and the explanation in its one gateway call,
and a full :class:`~relrl.monitor.view.StepView` is published; the learner's tree when it
changed (:class:`TreeWatch`). Episodes use
:class:`relrl.episodes.recording.SessionTap`, which adds frames, the head and the metrics.
"""

from __future__ import annotations

import json
import time
from typing import Any

from relrl.monitor.view import view_of

__all__ = ["LoopTap", "TreeWatch", "leaf_of"]


def leaf_of(explanation: dict[str, Any] | None, response: str | None) -> str | None:
    """The id (as text) of the leaf a step's response came from -- tg: the chosen
    response's own leaf -- or ``None`` when the explanation names none."""
    exp = explanation or {}
    for entry in exp.get("ranked") or ():
        if entry.get("response") == response and entry.get("leaf") is not None:
            return str(entry["leaf"])
    return None if exp.get("leaf") is None else str(exp["leaf"])


class TreeWatch:
    """When to ask a learner for its tree again: once every ``period`` seconds, and at once
    when a step's leaf is not in the tree last taken (the tree split), so the page never
    shows a unit's leaf missing for long. One query per check; :attr:`graph` is the tree.

    Args:
        learner: the learner (``graph()``).
        period: seconds between checks.
    """

    def __init__(self, learner: Any, period: float = 1.0) -> None:
        self.learner, self.period = learner, period
        self.graph: dict[str, Any] | None = None
        self._key: str | None = None
        self._ids: set[str] = set()
        self._missed: str | None = None
        self._next = 0.0

    def changed(self, leaf: str | None = None, *, force: bool = False) -> bool:
        """Check the tree when it is due (or ``force``, or ``leaf`` is not in it); whether
        it changed since the last check (then :attr:`graph` is the new one)."""
        from relrl.monitor.graph import shown_graph

        now = time.perf_counter()
        split = leaf is not None and leaf not in self._ids and leaf != self._missed
        if not (force or split or now >= self._next):
            return False
        self._next = now + self.period
        self.graph = shown_graph(self.learner, self.graph)
        self._ids = {str(n["id"]) for n in (self.graph or {}).get("nodes") or ()}
        if split and leaf not in self._ids:
            self._missed = leaf  # a learner whose leaves are not its graph's: asked once
        key = json.dumps(self.graph, sort_keys=True)
        if key == self._key:
            return False
        self._key = key
        return True


class LoopTap:
    """A control loop's ``on_step`` feeding a :class:`~relrl.monitor.hub.Hub`.

    Args:
        hub: the monitor's hub.
        agent: the agent whose steps are shown (its knowledge base and learner).
        phase: a label for the page.
        tree_period: seconds between checks of the learner's tree.
    """

    def __init__(self, hub: Any, agent: Any, phase: str = "", tree_period: float = 1.0) -> None:
        self.hub, self.agent, self.phase = hub, agent, phase
        self.tree = TreeWatch(agent.learner, tree_period)
        self.t = 0
        self._asked = False
        hub.info.setdefault("learner", agent.learner.name)
        hub.info.setdefault("necessities", agent.necessities)

    def want(self) -> tuple[str, ...]:
        """What the next step is to report (memory and explanation when a view is due)."""
        self._asked = self.hub.due()
        return ("memory", "explain") if self._asked else ()

    def __call__(self, record: Any) -> None:
        self.t += 1
        out = record.out
        hub = self.hub
        hub.tick(self.t, list(out.outputs.values()), float(out.reward))
        if not self._asked:
            return
        self._asked = False
        row = view_of(self.t, self.phase, record).row()
        hub.publish(row)
        if self.tree.changed(leaf_of(row["explanation"], row["response"])):
            hub.set_tree(self.tree.graph)
