"""The live monitor on any control loop (the simulator, an experiment, a script of yours):
``Interaction(env, agent, on_step=LoopTap(hub, agent))``.

Every step hands the necessity outputs and reward to the hub's plot; at the hub's rate a full
:class:`~relrl.monitor.view.StepView` (working memory with ages, the explanation) is built
and published; once a second the learner's tree. Episodes use
:class:`relrl.episodes.recording.SessionTap`, which adds frames, the head and the metrics.
"""

from __future__ import annotations

import time
from typing import Any

from relrl.monitor.view import view_of

__all__ = ["LoopTap"]


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
        self.tree_period = tree_period
        self._tree_next = 0.0
        self.t = 0
        hub.info.setdefault("learner", agent.learner.name)
        hub.info.setdefault("necessities", agent.necessities)

    def __call__(self, record: Any) -> None:
        self.t += 1
        out = record.out
        hub = self.hub
        hub.tick(self.t, list(out.outputs.values()), float(out.reward))
        if not hub.due():
            return
        learner = self.agent.learner
        view = view_of(self.t, self.phase, record, memory=self.agent.kb.memory(),
                       explanation=learner.explain())
        hub.publish(view.row())
        now = time.perf_counter()
        if now >= self._tree_next:
            from relrl.monitor.graph import learner_graph

            self._tree_next = now + self.tree_period
            hub.set_tree(learner_graph(learner))
