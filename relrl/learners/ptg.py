"""ptg: P-learning beside tg's Q-tree, held in Prolog (prolog/ptg.pl).

Relational reinforcement learning's P-learning (Džeroski, De Raedt & Driessens, 2001): beside
the Q-function, a first-order tree learns P(s, a) -- 1 when the Q-tree finds ``a`` optimal in
``s``, 0 when not -- and greedy choices are made by P (ties by Q). The optimal policy often
depends on the objects far less than the values do, so a P-tree learned in small worlds acts
in larger ones where the Q-tree's values mislead it. A learner of worlds
(``learner_serves(ptg, worlds, _)``); see docs/worlds.md.
"""

from __future__ import annotations

from typing import Any

from relrl.learners.base import Learner
from relrl.learners.registry import register
from relrl.learners.tg import explanation
from relrl.terms import Term

__all__ = ["PTGLearner"]


@register
class PTGLearner(Learner):
    """tg's Q-tree (learned and exploring as tg does) and a P-tree that acts when greedy.

    Its parameters are declared beside its hooks in prolog/ptg.pl: tg's (the Q-tree's) and
    p_margin (a response is labelled optimal when its Q is within this of the best
    response's), p_alpha (a P-leaf's estimate moves at rate max(1/n, p_alpha): its labels
    change as the Q-tree learns) and p_pairs (pairs of P-examples, one optimal response and
    one not, inserted per learning step). The P-tree splits as the Q-tree does
    (significance, min_examples, half_life, keep_examples). This class reads its
    explanations.
    """

    name = "ptg"

    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """``ranked``: every response's P, Q and P-leaf, by P then Q; ``paths``: for each, the
        P-tree's tests from the root to its leaf with the bindings that made them true;
        ``path`` and ``leaf``: the best response's."""
        _, choices = detail
        return explanation(state, [({"p": p, "q": q, "leaf": leaf}, action, path)
                                   for _, action, p, q, leaf, path in choices])
