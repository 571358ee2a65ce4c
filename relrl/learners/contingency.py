"""Contingency learning (section 4.1): behaviour rules with fitness, held in Prolog."""

from __future__ import annotations

from typing import Any

from relrl.errors import ConfigError
from relrl.learners.base import Learner
from relrl.learners.registry import register
from relrl.terms import Term, format_term

__all__ = ["ContingencyLearner"]


@register
class ContingencyLearner(Learner):
    """Roulette-wheel selection over behaviour rules (prolog/contingency.pl).

    Its parameters (default_fitness, influence, min_fitness, max_fitness, default_always,
    extinction, satiation) are declared beside its hooks in prolog/contingency.pl, with how
    the paper's section 4.1 is read (docs/engine.md, "Contingency"); the defaults are the
    fixed task's, and ``relrl experiment sis --preset paper-2012`` sets the paper's reading.
    This class checks how the fitness bounds relate, reads explanations and rules.
    """

    name = "contingency"

    def _check_params(self) -> None:
        """0 < min_fitness <= default_fitness <= max_fitness."""
        p = self.params
        if not 0 < p["min_fitness"] <= p["default_fitness"] <= p["max_fitness"]:
            raise ConfigError("need 0 < min_fitness <= default_fitness <= max_fitness, got "
                              f"{p['min_fitness']}, {p['default_fitness']}, {p['max_fitness']}")

    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """The responses with a matching rule, highest summed fitness first."""
        _, ranked = detail
        return {"ranked": [{"response": format_term(r), "fitness": f} for (_, r, f) in ranked]}

    def rules(self) -> list[tuple[Term, Term, Term, float]]:
        """Every behaviour rule: (antecedent, response, necessity, fitness), authored first."""
        return [tuple(r[1:]) for r in self._engine().knowledge()]  # type: ignore[misc]
