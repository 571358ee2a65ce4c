"""Learners, looked up by name in the registry relrl's Prolog declares
(:mod:`relrl.learners.registry`): ``contingency``, ``etg``, ``qlearning`` and ``tg`` learn
the domains; ``tg``, ``ptg`` and ``qtable`` learn worlds (in prolog/learners.pl's order).

Example:
    >>> from relrl.learners import learners, make_learner
    >>> learners("domains")
    ('contingency', 'etg', 'qlearning', 'tg')
    >>> learner = make_learner("etg", epsilon=0.1)
"""

from relrl.learners import contingency, etg, ptg, qlearning, qtable, tg  # noqa: F401  (registers them)
from relrl.learners.base import DOMAINS, WORLDS, Learner, LearnerSpec, Parameter, StepOut
from relrl.learners.registry import (
    learner_spec,
    learners,
    make_learner,
    make_world_learner,
    register,
)

__all__ = ["DOMAINS", "WORLDS", "Learner", "LearnerSpec", "Parameter", "StepOut",
           "learner_spec", "learners", "make_learner", "make_world_learner", "register"]
