"""Experiment 2 of da Silva & Romero (2012, section 5.2): gaze following with fruits, then
declarative pointing (naming the fruit), on the episode world.

* :mod:`~relrl.experiments.exp2.measures` -- its two measurements: the CGI evaluations
  (Fig. 6) and the naming executions with their outcome counts (Table 1), which an episode
  (``relrl run examples/episodes/experiment2.toml``) takes;
* :mod:`~relrl.experiments.exp2.sweep` -- the episode over seeds, learners and both readings of
  the time unit, ``python -m relrl.experiments.exp2 --seeds 0-4 --out docs/results/exp2``.
"""

from relrl.experiments.exp2.measures import (
    OUTCOMES,
    PAPER,
    Naming,
    evaluate_cgi,
    naming_execution,
    rates,
    table1,
)

__all__ = ["OUTCOMES", "PAPER", "Naming", "evaluate_cgi", "naming_execution", "rates",
           "table1"]
