"""Learners, looked up by name: ``contingency``, ``qlearning``, ``etg``.

Example:
    >>> from relrl.learners import make_learner
    >>> learner = make_learner("etg", epsilon=0.1)
"""

from relrl.learners import contingency, etg, qlearning  # noqa: F401  (registers them)
from relrl.learners.base import LEARNERS, Learner, StepOut, make_learner, register

__all__ = ["LEARNERS", "Learner", "StepOut", "make_learner", "register"]
