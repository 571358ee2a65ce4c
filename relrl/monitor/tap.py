"""The live monitor on any control loop (the simulator, an experiment, a script of yours)::

    tap = LoopTap(hub, agent)
    interaction = Interaction(env, agent, on_step=tap)
    for _ in range(steps):
        interaction.run(1, keep=False, want=tap.want())

Every step hands the necessity outputs and reward to the hub's plot; at the hub's rate the
step is asked (``want``) for working memory and the explanation in its one gateway call,
and a full :class:`~relrl.monitor.view.StepView` is published; once a second the learner's
tree. Episodes use
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
        learner = self.agent.learner
        hub.publish(view_of(self.t, self.phase, record).row())
        now = time.perf_counter()
        if now >= self._tree_next:
            from relrl.monitor.graph import shown_graph

            self._tree_next = now + self.tree_period
            hub.set_tree(shown_graph(learner, hub.tree))
