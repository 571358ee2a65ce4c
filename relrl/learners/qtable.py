"""qtable: Q-learning over ground relational states, in Prolog (prolog/world_qtable.pl).

The baseline of worlds written in Prolog: a table keyed on the ground view of the state and
the ground action, so nothing learned in one state carries to another that differs only in
its objects' names, and nothing carries to a world of another size. It is a learner of
worlds only (relrl.worlds.WORLD_LEARNERS), not of the domains' experiments, whose tabular
baseline is ``qlearning`` over the 2^x state code.
"""

from __future__ import annotations

from typing import Any

from relrl.learners.base import Learner
from relrl.terms import Term, format_term

__all__ = ["QTableLearner"]


class QTableLearner(Learner):
    """Tabular Q-learning over ground relational states (one call a step, or a batch of
    episodes in a world). Parameters: alpha, gamma, epsilon (with temperature 0:
    epsilon-greedy), temperature (> 0: Boltzmann), q_init."""

    name = "qtable"
    engine_name = "qtable"
    defaults = {"alpha": 0.5, "gamma": 0.9, "epsilon": 0.1, "temperature": 0.0,
                "q_init": 0.0}

    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """``ranked``: the table's entries for the state, best first."""
        _, pairs = detail
        ranked = [{"response": format_term(a), "q": q} for (_, q, a) in pairs]
        return {"state": [format_term(f) for f in state], "ranked": ranked}
