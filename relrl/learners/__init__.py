"""Learners, looked up by name: ``contingency``, ``qlearning``, ``etg``, ``tg``.

Example:
    >>> from relrl.learners import make_learner
    >>> learner = make_learner("etg", epsilon=0.1)
"""

from relrl.learners import contingency, etg, qlearning, tg  # noqa: F401  (registers them)
from relrl.learners.base import LEARNERS, Learner, StepOut, make_learner, register

__all__ = ["LEARNERS", "Learner", "StepOut", "make_learner", "register"]
