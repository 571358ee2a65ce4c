"""Python values to Prolog terms and back, through the foreign interface.

The values are those of :mod:`relrl.terms` (an atom is a ``str``, a compound a tuple with
its name first, a list a ``list``, an unbound variable a :class:`~relrl.terms.Var`). Text
from outside is always passed as a value, never pasted into a goal's text.

:class:`Cached` marks a ground term that recurs (a percept list of the simulator): it is
built once and then copied from Prolog's record database, one foreign call instead of one
per node.
"""

from __future__ import annotations

import ctypes
from ctypes import byref, c_char_p, c_double, c_int64, c_size_t
from fractions import Fraction
from typing import Any

from relrl.bridge import lib as L
from relrl.errors import AnswerTooLarge, RelrlError
from relrl.terms import Term, Var

__all__ = ["Cached", "Marshal", "MAX_DEPTH", "MAX_LIST"]

#: Deepest nesting of a term passed from Prolog to Python (deeper, or cyclic, raises).
MAX_DEPTH = 400
#: Longest list passed from Prolog to Python.
MAX_LIST = 10_000_000
#: Most atoms and records kept in a cache before it is emptied (what it holds is freed).
CACHE_SIZE = 4096
#: Texts read from one answer between two releases of SWI-Prolog's string buffers (each
#: text is copied at once; SWI-Prolog aborts the process above some 600,000 buffers held).
TEXTS_PER_RELEASE = 50_000


class Cached:
    """A ground term that recurs, recorded in Prolog on first use (see the module
    documentation).

    Args:
        value: the term (ground: no :class:`~relrl.terms.Var`).
        key: a hashable key equal for equal terms (default: ``value`` made hashable).
    """

    __slots__ = ("value", "key")

    def __init__(self, value: Term, key: Any = None) -> None:
        self.value = value
        self.key = key if key is not None else _hashable(value)


_LIST_KEY = object()   # marks a list's key: no compound's key starts with it


def _hashable(value: Term) -> Any:
    # Equal keys must mean equal terms: 1, 1.0 and True are equal in Python but not in
    # Prolog, and a list is not a compound. A string never equals a number or a tuple.
    kind = type(value)
    if kind is str:
        return value
    if kind is tuple:
        if all(type(item) is str for item in value):
            return value          # atoms only (most percepts): the tuple is its own key
        return tuple(map(_hashable, value))
    if kind is list:
        if all(type(item) is tuple and all(type(a) is str for a in item) for item in value):
            return (_LIST_KEY, *value)          # a percept list: keyed as it is
        return (_LIST_KEY, *map(_hashable, value))
    return (kind.__name__, value)


class Marshal:
    """Term conversion both ways, with the caches that make it cheap: atoms, functors and
    records (:class:`Cached`) made once.

    Args:
        lib: the started library.
    """

    def __init__(self, lib: L.Lib) -> None:
        self.lib = lib
        self._atoms: dict[str, int] = {}
        self._functors: dict[tuple[str, int], int] = {}
        self._held: dict[int, str] = {}      # atom handle -> name, for the process's life
        self._held_names: dict[str, int] = {}
        self.records: dict[Any, int] = {}
        self._size, self._text_ptr = c_size_t(), c_char_p()
        #: the string buffers' mark of the crossing whose answers are read (set by the
        #: caller that marked; None: texts are not released while an answer is read)
        self.mark: c_size_t | None = None
        self._texts = 0                      # texts read since the last release

    # -- atoms, functors, records ----------------------------------------------------------

    def _new_atom(self, name: str) -> int:
        data = name.encode("utf-8")
        atom = self.lib.new_atom_mbchars(L.REP_UTF8, len(data), data)
        if not atom:
            raise RelrlError(f"cannot make an atom of {name!r}")
        return atom

    def atom(self, name: str) -> int:
        """The handle of atom ``name`` (cached; the cache holds a reference)."""
        atom = self._atoms.get(name)
        if atom is None:
            atom = self._new_atom(name)
            if len(self._atoms) >= CACHE_SIZE:      # keep the cache (and what it holds) small
                for old in self._atoms.values():
                    self.lib.unregister_atom(old)
                self._atoms.clear()
            self._atoms[name] = atom
        return atom

    def hold(self, name: str) -> int:
        """The handle of atom ``name``, kept for the life of the process: the step reads
        atoms it holds (:meth:`held`) by handle, without converting text."""
        atom = self._held_names.get(name)
        if atom is None:
            atom = self._held_names[name] = self._new_atom(name)
            self._held[atom] = name
        return atom

    def held(self, atom: int) -> str | None:
        """The name of a held atom (None for an atom not held)."""
        return self._held.get(atom)

    def functor(self, name: str, arity: int) -> int:
        key = (name, arity)
        f = self._functors.get(key)
        if f is None:
            f = self._functors[key] = self.lib.new_functor_sz(self._new_atom(name), arity)
        return f

    def record(self, value: Cached, table: dict[Any, int] | None = None) -> int:
        """The handle of ``value``'s record in ``table`` (:attr:`records` by default),
        made on first use. A later record of the same table may evict it: use it first."""
        table = self.records if table is None else table
        rec = table.get(value.key)
        if rec is None:
            lib = self.lib
            fid = lib.open_foreign_frame()
            try:
                t = lib.new_term_ref()
                self.put(t, value.value, {})
                if len(table) >= CACHE_SIZE:       # keep the table (and what it holds) small
                    for old in table.values():
                        lib.erase(old)
                    table.clear()
                rec = table[value.key] = lib.record(t)
            finally:
                lib.discard_foreign_frame(fid)
        return rec

    # -- Python -> Prolog ------------------------------------------------------------------

    def put(self, t: int, value: Term, variables: dict[int, int]) -> None:
        """Write ``value`` into term reference ``t`` (``variables``: the references of the
        :class:`~relrl.terms.Var` objects met so far in this call)."""
        lib = self.lib
        if isinstance(value, str):
            lib.put_atom(t, self.atom(value))
        elif isinstance(value, bool):
            lib.put_atom(t, self.atom("true" if value else "false"))
        elif isinstance(value, int):
            if -(2**63) <= value < 2**63:
                lib.put_int64(t, value)
            else:
                lib.chars_to_term(str(value).encode(), t)
        elif isinstance(value, float):
            lib.put_float(t, value)
        elif isinstance(value, tuple):
            if not value or not isinstance(value[0], str):
                raise TypeError(f"a compound term is (name, args...), not {value!r}")
            if len(value) == 1:
                lib.put_atom(t, self.atom(value[0]))
                return
            n = len(value) - 1
            a0 = lib.new_term_refs(n)
            for i, arg in enumerate(value[1:]):
                self.put(a0 + i, arg, variables)
            lib.cons_functor_v(t, self.functor(value[0], n), a0)
        elif isinstance(value, list):
            lib.put_nil(t)
            if value:
                head = lib.new_term_ref()
                for item in reversed(value):
                    self.put(head, item, variables)
                    lib.cons_list(t, head, t)
        elif isinstance(value, Cached):
            lib.recorded(self.record(value), t)
        elif isinstance(value, Var):
            known = variables.get(id(value))
            if known is None:
                lib.put_variable(t)
                variables[id(value)] = t
            else:
                lib.put_term(t, known)
        elif hasattr(value, "item") and callable(value.item):  # numpy scalar
            self.put(t, value.item(), variables)
        else:
            raise TypeError(f"cannot pass {type(value).__name__} {value!r} to Prolog")

    # -- Prolog -> Python ------------------------------------------------------------------

    def _text(self, t: int, flags: int) -> str:
        """Text of the term at ``t`` (the caller marks and releases the string stack; with
        :attr:`mark` set, the buffers of the texts copied are released every
        :data:`TEXTS_PER_RELEASE` texts, so an answer of any size can be read)."""
        if not self.lib.get_nchars(t, byref(self._size), byref(self._text_ptr),
                                   flags | L.REP_UTF8):
            raise RelrlError("cannot read text from a Prolog term")
        text = ctypes.string_at(self._text_ptr, self._size.value).decode("utf-8")
        self._texts += 1
        if self._texts >= TEXTS_PER_RELEASE and self.mark is not None:
            self._texts = 0
            self.lib.release_string_buffers_from_mark(self.mark.value)
        return text

    def atom_name(self, atom: int) -> str:
        """The name of the atom with handle ``atom``."""
        name = self._held.get(atom)
        if name is None:
            self.lib.atom_mbchars(atom, byref(self._size), byref(self._text_ptr), L.REP_UTF8)
            name = ctypes.string_at(self._text_ptr, self._size.value).decode("utf-8")
        return name

    def get(self, t: int, depth: int = 0) -> Term:
        """The term at reference ``t`` as a Python value.

        Raises:
            AnswerTooLarge: the term is nested deeper than :data:`MAX_DEPTH` (or cyclic), or
                holds a list longer than :data:`MAX_LIST` (or cyclic).
        """
        if depth > MAX_DEPTH:
            raise AnswerTooLarge(f"a term nested deeper than {MAX_DEPTH} levels (or cyclic) "
                                 "cannot be passed to Python", "term_too_deep")
        lib = self.lib
        kind = lib.term_type(t)
        if kind == L.ATOM:
            return self._text(t, L.CVT_ATOM)
        if kind == L.INTEGER:
            v = c_int64()
            return v.value if lib.get_int64(t, byref(v)) else int(self._text(t, L.CVT_INTEGER))
        if kind == L.FLOAT:
            d = c_double()
            lib.get_float(t, byref(d))
            return d.value
        if kind == L.STRING:
            return self._text(t, L.CVT_STRING)
        if kind == L.NIL:
            return []
        if kind == L.LIST_PAIR:
            return self._list(t, depth)
        if kind == L.TERM:
            name, arity = c_size_t(), c_size_t()
            lib.get_name_arity_sz(t, byref(name), byref(arity))
            arg = lib.new_term_ref()
            values = [self.atom_name(name.value)]
            for i in range(1, arity.value + 1):
                lib.get_arg_sz(i, t, arg)
                values.append(self.get(arg, depth + 1))
            return tuple(values)
        if kind == L.VARIABLE:
            return Var(self._text(t, L.CVT_VARIABLE))
        if kind == L.RATIONAL:
            return Fraction(self._text(t, L.CVT_WRITEQ).replace("r", "/"))   # 1r3
        return self._text(t, L.CVT_WRITEQ)          # a blob (a stream, ...), a dict

    def _list(self, t: int, depth: int) -> Term:
        lib = self.lib
        items = []
        head, rest = lib.new_term_ref(), lib.new_term_ref()
        lib.put_term(rest, t)
        while lib.get_list(rest, head, rest):
            items.append(self.get(head, depth + 1))
            if len(items) > MAX_LIST:
                raise AnswerTooLarge(f"a list longer than {MAX_LIST} elements (or cyclic) "
                                     "cannot be passed to Python", "list_too_long")
        if lib.term_type(rest) == L.NIL:
            return items
        value: Term = self.get(rest, depth + 1)      # a partial list [a, b|T]: as the
        for item in reversed(items):                # '[|]' compounds it is made of
            value = ("[|]", item, value)
        return value
