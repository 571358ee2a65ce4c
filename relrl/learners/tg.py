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

    Its parameters are declared beside its hooks in prolog/tg.pl, with their defaults in
    the domains and in worlds (chosen by measurement, see docs/tg.md): alpha (0: a leaf's
    Q is the mean of its Q-targets; otherwise the step size is max(1/n, alpha)), gamma,
    temperature (> 0: Boltzmann exploration, P(a) proportional to exp(Q(s, a) / T), while
    learning and in the behaviour evaluation), epsilon (used only with temperature 0:
    epsilon-greedy), q_init (Q of the first, empty leaf), significance (of the F-test of
    the best of a leaf's candidates, Bonferroni-corrected for their number; the leaves keep
    the statistics of the TD errors), min_examples (a split must leave at least this many
    examples on each side), stale_bonus (while learning, a leaf no example has reached for
    the last k examples counts Q + stale_bonus * sqrt(k): Dyna-Q+'s exploration bonus, per
    leaf; 0 turns it off), half_life (an example counts half in the split statistics once
    this many more examples have been inserted; 0: never forget), novelty_bonus and
    novelty_confidence (directed exploration while learning: Q(s, a) counts as Q + the
    largest upper confidence bound, mean TD error + novelty_confidence standard errors, of
    the regions (s, a) falls in — its leaf and the yes-side of each candidate test of the
    leaf that succeeds on it — capped at novelty_bonus, which is also the bound of a region
    fewer than two examples reached; novelty_bonus 0 turns it off), keep_examples (each
    leaf keeps its last examples so that a split's children start with statistics; 0: they
    start empty), action_gap (advantage learning: each Q-target is lowered by action_gap
    times the gap between the best Q of the example's state and the example's own Q, so
    that a leaf's value ranks moves within a state rather than states; 0 in the domains,
    0.5 in worlds). Explore and greedy choices and the Q-targets never include the bonuses.
    Choices are over classes of responses no test of the bias tells apart in the state
    (scored by one representative, uniform within a class). This class reads its
    explanations.
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
