"""relrl: relational reinforcement learning for social robots.

Knowledge (declarations, working memory, state code, rules, the ETG tree) lives in SWI-Prolog,
reached through one gateway (:mod:`relrl.kb`); numbers, pixels and wires live in Python.
"""

from __future__ import annotations

__version__ = "0.2.0"

__all__ = ["__version__"]
