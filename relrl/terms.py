"""Prolog terms as plain Python values.

The gateway (:mod:`relrl.kb`) converts between Prolog terms and these Python values, both
ways, keeping structure:

============================  =====================================================
Prolog                        Python
============================  =====================================================
atom ``face``                 ``"face"`` (str)
integer, float                ``int``, ``float``
string ``"hello"``            ``"hello"`` (str; an atom when sent back)
list ``[a, b]``               ``["a", "b"]`` (a partial list ``[a|T]`` is ``("[|]", "a", T)``)
compound ``pose(face, left)`` ``("pose", "face", "left")`` — functor first
unbound variable              :class:`Var`
============================  =====================================================

Text from outside (a percept, a word the caregiver says) is always passed as data in one of
these values, never pasted into a goal string.
"""

from __future__ import annotations

import re
from typing import Any

__all__ = ["Var", "Term", "compound", "format_term", "functor", "args", "split_terms"]

#: A Prolog term as a Python value (see the module documentation).
Term = Any

_SOLO = re.compile(r"^[a-z][A-Za-z0-9_]*$")
_SYMBOLIC = re.compile(r"^[-+*/\\^<>=~:.?@#&$]+$")
_SPECIAL_ATOMS = {"[]", "!", ";", "{}", ","}


class Var:
    """An unbound Prolog variable: an output argument, or a variable in a result.

    Within one call, the same :class:`Var` object stands for the same Prolog variable.
    """

    __slots__ = ("name",)

    def __init__(self, name: str = "_") -> None:
        self.name = name

    def __repr__(self) -> str:
        return f"Var({self.name!r})"


def compound(name: str, *arguments: Term) -> tuple:
    """Build the compound term ``name(arguments...)``.

    Example:
        >>> compound("pose", "face", "left_1")
        ('pose', 'face', 'left_1')
    """
    if not arguments:
        raise ValueError(f"a compound needs arguments; the atom {name!r} is just the string")
    return (name, *arguments)


def functor(term: Term) -> tuple[str, int]:
    """Return ``(name, arity)`` of an atom or compound term."""
    if isinstance(term, tuple):
        return term[0], len(term) - 1
    if isinstance(term, str):
        return term, 0
    raise TypeError(f"not an atom or compound: {term!r}")


def args(term: Term) -> tuple:
    """Return the arguments of a compound term (empty for an atom)."""
    return term[1:] if isinstance(term, tuple) else ()


def _quote_atom(name: str) -> str:
    if _SOLO.match(name) or _SYMBOLIC.match(name) or name in _SPECIAL_ATOMS:
        return name
    escaped = name.replace("\\", "\\\\").replace("'", "\\'").replace("\n", "\\n")
    return f"'{escaped}'"


def format_term(term: Term) -> str:
    """Write a term as Prolog text, quoting atoms where Prolog needs quotes.

    Example:
        >>> format_term(("at", "object", "left_down"))
        'at(object,left_down)'
        >>> format_term(("hear", "Apple"))
        "hear('Apple')"
    """
    if isinstance(term, bool):
        return "true" if term else "false"
    if isinstance(term, str):
        return _quote_atom(term)
    if isinstance(term, int):
        return str(term)
    if isinstance(term, float):
        text = repr(term)
        return text if any(c in text for c in ".en") else text + ".0"
    if isinstance(term, list):
        return "[" + ",".join(format_term(t) for t in term) + "]"
    if isinstance(term, tuple):
        if len(term) == 1:
            return _quote_atom(term[0])
        return _quote_atom(term[0]) + "(" + ",".join(format_term(t) for t in term[1:]) + ")"
    if isinstance(term, Var):
        return "_" if term.name.startswith("_") else term.name
    raise TypeError(f"cannot write {term!r} as a Prolog term")


_OPEN, _CLOSE = "([{", ")]}"


def split_terms(text: str) -> list[str]:
    """A comma-separated list of terms as typed (``--tasks stack,on(b1, b2)``), split at
    the commas outside brackets and quotes only: ``on(b1,b2)`` stays one term. Blank
    items are dropped; each item is stripped (its own reader says whether it is a term)."""
    items, depth, quote, start, i = [], 0, "", 0, 0
    while i < len(text):
        c = text[i]
        if quote:
            if c == "\\":
                i += 1
            elif c == quote:
                quote = ""
        elif c in "'\"`":
            quote = c
        elif c in _OPEN:
            depth += 1
        elif c in _CLOSE:
            depth = max(0, depth - 1)
        elif c == "," and depth == 0:
            items.append(text[start:i])
            start = i + 1
        i += 1
    items.append(text[start:])
    return [item.strip() for item in items if item.strip()]
