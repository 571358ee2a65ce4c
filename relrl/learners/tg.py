"""TG: a first-order incremental regression-tree Q-learner, held in Prolog (prolog/tg.pl).

In the line of RRL-TG (Driessens, Ramon & Blockeel, ECML 2001): one regression tree over
(relational state, action, necessity) examples whose tests are conjunctions of literals
from the domain's language bias (``rmode/1``: typed variables, constants only where the
task needs them), split by an F-test on incremental statistics of the TD errors; choices
and Q-targets over classes of responses the bias cannot tell apart, so its work and memory
do not grow with the world. See docs/tg.md.
"""

from __future__ import annotations

from typing import Any

from relrl.learners.base import Learner
from relrl.learners.registry import register
from relrl.terms import Term, format_term

__all__ = ["TGLearner", "explanation"]


@register
class TGLearner(Learner):
    """A first-order Q-tree; choices, updates and splits run in Prolog (one call a step).

    Its parameters, their defaults and the worlds' defaults are declared once, beside its
    hooks in prolog/tg.pl (``learner_parameter/4`` and ``learner_serves/3``, read by
    :func:`relrl.learners.learner_spec`); docs/tg.md's table says what each does (a test
    holds the table to the declarations). Explore and greedy choices and the Q-targets
    never include the exploration bonuses. Choices are over classes of responses no test
    of the bias tells apart in the state (scored by one representative, uniform within a
    class). This class reads its explanations.
    """

    name = "tg"

    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """``ranked``: every response's Q and leaf, best first; ``paths``: for each, the
        first-order tests from the root to its leaf, with the bindings that made them
        true; ``path`` and ``leaf``: the best response's."""
        _, choices = detail
        return explanation(state, [({"q": q, "leaf": leaf}, action, path)
                                   for _, action, q, leaf, path in choices])


def explanation(state: Term, choices: list[tuple[dict[str, Any], Term, Term]]
                ) -> dict[str, Any]:
    """A tree learner's explanation as :meth:`explain` returns it, from its Prolog side's
    choices, best first: each is (the response's figures, the response, its path of tests,
    each ``test(_, _, Text, Outcome, Bindings)``)."""
    ranked, paths = [], {}
    for figures, action, path in choices:
        response = format_term(action)
        ranked.append({"response": response, **figures})
        paths[response] = [{"test": str(text), "holds": outcome == "true",
                            "bindings": {str(b[1]): format_term(b[2]) for b in bindings}}
                           for (_, _, text, outcome, bindings) in path]
    best = ranked[0]["response"] if ranked else None
    return {"state": [format_term(f) for f in state], "ranked": ranked, "paths": paths,
            "path": paths.get(best, []) if best else [],
            "leaf": ranked[0]["leaf"] if ranked else None}
