"""Perception facts as plain Python values, and their Prolog text.

A fact is a Prolog term written in Python: a compound term is a tuple ``(functor, arg1, ...)``
with a ``str`` functor, an atom is a ``str``, numbers are ``int``/``float`` and lists are Python
lists. For example ``("pose", "face", "left_1")`` is ``pose(face, left_1)``.
"""

from __future__ import annotations

import math
import re

__all__ = ["Fact", "format_fact", "format_term"]

Fact = tuple | str | int | float | list

_PLAIN_ATOM = re.compile(r"^[a-z][a-zA-Z0-9_]*$")


def _atom(name: str) -> str:
    if _PLAIN_ATOM.match(name) or name == "[]":
        return name
    return "'" + name.replace("\\", "\\\\").replace("'", "\\'") + "'"


def format_term(term: Fact) -> str:
    """Prolog text of a term (no final full stop).

    Raises:
        TypeError: for a value with no Prolog reading (None, dict, NaN, ...).
    """
    if isinstance(term, bool):
        raise TypeError(f"no Prolog term for the bool {term!r}; use an atom 'true'/'false'")
    if isinstance(term, str):
        return _atom(term)
    if isinstance(term, int):
        return str(term)
    if isinstance(term, float):
        if not math.isfinite(term):
            raise TypeError(f"no Prolog term for the float {term!r}")
        return repr(term)
    if isinstance(term, list):
        return "[" + ", ".join(format_term(t) for t in term) + "]"
    if isinstance(term, tuple) and term and isinstance(term[0], str):
        if len(term) == 1:
            return _atom(term[0])
        return _atom(term[0]) + "(" + ", ".join(format_term(t) for t in term[1:]) + ")"
    raise TypeError(f"no Prolog term for {term!r}; use a tuple (functor, args...), str, "
                    "int, float or list")


def format_fact(fact: Fact) -> str:
    """A fact as a Prolog clause, e.g. ``see(face).``."""
    return format_term(fact) + "."
