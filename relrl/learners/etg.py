"""ETG: the Economic TG learner (Algorithms 2 and 3, Eq. 4), held in Prolog (prolog/etg.pl)."""

from __future__ import annotations

from typing import Any

from relrl.learners.base import Learner
from relrl.learners.registry import register
from relrl.terms import Term, format_term

__all__ = ["ETGLearner"]


@register
class ETGLearner(Learner):
    """A relational Q-tree grown one example per step; choices and updates run in Prolog.

    Its parameters (alpha, gamma, epsilon, q_init, split_threshold) are declared beside its
    hooks in prolog/etg.pl; this class reads its explanations.
    """

    name = "etg"

    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """The path of tests from the root (with outcomes), the leaf, its ranked entries."""
        _, path, ranked = detail
        tests = [{"test": format_term(step[1]), "holds": step[2] == "true"}
                 for step in path if isinstance(step, tuple) and step[0] == "-"]
        end = path[-1]
        return {"path": tests, "leaf": end[1] if isinstance(end, tuple) else None,
                "ranked": [{"response": format_term(a), "q": q} for (_, a, q, _) in ranked]}
