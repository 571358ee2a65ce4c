"""qtable: Q-learning over ground relational states, in Prolog (prolog/world_qtable.pl).

The baseline of worlds written in Prolog: a table keyed on the ground view of the state and
the ground action, so nothing learned in one state carries to another that differs only in
its objects' names, and nothing carries to a world of another size. It is a learner of
worlds only (``learner_serves(qtable, worlds, _)``), not of the domains' experiments, whose
tabular baseline is ``qlearning`` over the 2^x state code.
"""

from __future__ import annotations

from typing import Any

from relrl.learners.base import Learner
from relrl.learners.registry import register
from relrl.terms import Term, format_term

__all__ = ["QTableLearner"]


@register
class QTableLearner(Learner):
    """Tabular Q-learning over ground relational states (one call a step, or a batch of
    episodes in a world). Its parameters (alpha, gamma, epsilon, temperature, q_init) are
    declared beside its hooks in prolog/world_qtable.pl; this class reads its
    explanations."""

    name = "qtable"

    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """``ranked``: the table's entries for the state, best first."""
        _, pairs = detail
        ranked = [{"response": format_term(a), "q": q} for (_, q, a) in pairs]
        return {"state": [format_term(f) for f in state], "ranked": ranked}
