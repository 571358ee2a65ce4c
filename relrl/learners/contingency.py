"""Contingency learning (section 4.1): behaviour rules with fitness, held in Prolog."""

from __future__ import annotations

from typing import Any

from relrl.learners.base import Learner, register
from relrl.terms import Term, format_term

__all__ = ["ContingencyLearner"]


@register
class ContingencyLearner(Learner):
    """Roulette-wheel selection over behaviour rules (prolog/contingency.pl).

    Parameters: default_fitness (slice of a response with no matching rule), influence
    (how much a consequence moves a rule's fitness), min_fitness and max_fitness; and how the
    paper's section 4.1 is read (docs/engine.md, "Contingency"): default_always (1: every
    response keeps the default slice, its rules' fitness added to it), extinction (how much
    of the influence rate a response followed by no reinforcer loses: 1 or 0), satiation (1:
    a reinforcer that comes when no necessity is active lowers the rule). The defaults are
    the fixed task's; ``relrl experiment sis --preset paper-2012`` sets the paper's reading.
    """

    name = "contingency"
    engine_name = "contingency"
    defaults = {"default_fitness": 1.0, "influence": 0.5, "min_fitness": 0.05,
                "max_fitness": 10.0, "default_always": 0.0, "extinction": 1.0,
                "satiation": 0.0}

    def _check_params(self) -> None:
        super()._check_params()
        from relrl.errors import ConfigError

        p = self.params
        if not 0 < p["min_fitness"] <= p["default_fitness"] <= p["max_fitness"]:
            raise ConfigError("need 0 < min_fitness <= default_fitness <= max_fitness, got "
                              f"{p['min_fitness']}, {p['default_fitness']}, {p['max_fitness']}")
        for name in ("default_always", "satiation"):
            if p[name] not in (0.0, 1.0):
                raise ConfigError(f"{name} must be 0 or 1, not {p[name]}")
        if not 0.0 <= p["extinction"] <= 1.0:
            raise ConfigError(f"extinction must be in [0, 1], not {p['extinction']}")

    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """The responses with a matching rule, highest summed fitness first."""
        _, ranked = detail
        return {"ranked": [{"response": format_term(r), "fitness": f} for (_, r, f) in ranked]}

    def rules(self) -> list[tuple[Term, Term, Term, float]]:
        """Every behaviour rule: (antecedent, response, necessity, fitness), authored first."""
        return [tuple(r[1:]) for r in self._engine().knowledge()]  # type: ignore[misc]
