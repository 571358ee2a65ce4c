"""The one gateway to Prolog.

This is the only module of relrl that imports pyswip. It

* starts SWI-Prolog lazily, on the first knowledge base, and loads relrl's knowledge layer
  (``prolog/``);
* gives each :class:`KnowledgeBase` a Prolog module of its own, so two knowledge bases in one
  process never see each other's clauses or working memory;
* consults domain files and raises :class:`~relrl.errors.PrologLoadError` naming file and line
  (pyswip itself prints consult errors and carries on);
* passes values as terms built through the foreign interface — text from outside is data,
  never pasted into a goal string;
* runs every goal once under a time limit (a runaway rule raises
  :class:`~relrl.errors.QueryTimeout` instead of freezing the robot's loop), always closing
  the query and discarding its frame;
* returns plain Python values with structure kept (see :mod:`relrl.terms`).

pyswip gives one Prolog engine per process and it is not safe across threads: a gateway
call from a thread other than the one that started Prolog raises. Parallel experiments use
processes.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import re
import signal
import threading
import time
from collections.abc import Iterable, Iterator, Sequence
from ctypes import POINTER, byref, c_char_p, c_double, c_int, c_int64, c_size_t, c_uint, c_void_p
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NoReturn

from relrl.errors import (
    PolicyError,
    PrologError,
    PrologLoadError,
    QueryTimeout,
    RelrlError,
    RuleError,
)
from relrl.resources import prolog_dir
from relrl.terms import Term, Var

__all__ = ["KnowledgeBase", "Problem", "Cached", "PROLOG_DIR", "gateway_calls", "DEFAULT_TIMEOUT"]

#: Where the knowledge layer's .pl files live: package data (override with RELRL_PROLOG_DIR).
PROLOG_DIR = prolog_dir()

#: Seconds a single gateway call may run before it raises QueryTimeout.
DEFAULT_TIMEOUT = 10.0
#: Bytes of Prolog stack (all stacks together) before a rule raises a resource error.
STACK_LIMIT = 512 * 1024 * 1024
#: Deepest nesting of a term passed from Prolog to Python (deeper, or cyclic, raises).
MAX_DEPTH = 400
#: Longest list passed from Prolog to Python.
MAX_LIST = 10_000_000

# SWI-Prolog 9 foreign-interface constants.
_PL_VARIABLE, _PL_ATOM, _PL_INTEGER, _PL_RATIONAL, _PL_FLOAT = 1, 2, 3, 4, 5
_PL_STRING, _PL_TERM, _PL_NIL, _PL_BLOB, _PL_LIST_PAIR = 6, 7, 8, 9, 10
_REP_UTF8 = 0x00100000
_CVT_ATOM, _CVT_STRING, _CVT_INTEGER, _CVT_VARIABLE = 0x1, 0x2, 0x8, 0x40
_CVT_WRITEQ = 0xC0
_BUF_DISCARDABLE = 0x0
_PL_Q_NODEBUG, _PL_Q_CATCH_EXCEPTION = 0x04, 0x08

# relrl._read_kernel's codes (that module imports numba: it is loaded on first use).
_R_ATOM, _R_INT, _R_FLOAT, _R_STRING, _R_NIL, _R_LIST, _R_TERM, _R_OTHER = range(8)
_R_ROOT = -1
_FULL, _DEEP, _LONG = -1, -2, -3


def _too_deep() -> PrologError:
    return PrologError(f"a term nested deeper than {MAX_DEPTH} levels (or cyclic) cannot be "
                       "passed to Python", "term_too_deep")


def _too_long() -> PrologError:
    return PrologError(f"a list longer than {MAX_LIST} elements (or cyclic) cannot be passed "
                       "to Python", "list_too_long")


def _grown(array: Any) -> Any:
    """``array`` twice as long (first axis), zeroed: a compiled reader's room."""
    import numpy as np

    return np.zeros((2 * array.shape[0], *array.shape[1:]), array.dtype)


_KB_MODULE = re.compile(r"\brelrl_kb_\d+:")
_MAX_RECORDS = 4096
_MAX_ATOMS = 4096


class Cached:
    """A ground term that recurs (a percept list of the simulator): built in Prolog once,
    then copied from Prolog's record database, one foreign call instead of one per node.

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
        for item in value:
            if type(item) is not str:
                return tuple(map(_hashable, value))
        return value          # atoms only (most percepts): the tuple is its own key
    if kind is list:
        for item in value:             # a percept list: tuples of atoms, keyed as they are
            if type(item) is not tuple:
                break
            for arg in item:
                if type(arg) is not str:
                    break
            else:
                continue
            break
        else:
            return (_LIST_KEY, *value)
        return (_LIST_KEY, *map(_hashable, value))
    return (kind.__name__, value)


@dataclass(frozen=True)
class Problem:
    """One error or warning printed while loading a file."""

    kind: str          # "error" or "warning"
    path: str
    line: int | None
    message: str

    def __str__(self) -> str:
        where = f"{self.path}:{self.line}" if self.line else self.path
        return f"{where}: {self.kind}: {self.message}"


class _Engine:
    """The process's one Prolog engine and the foreign-interface calls relrl uses."""

    def __init__(self) -> None:
        import pyswip.prolog  # noqa: F401  (starts Prolog; must come before core use)
        from pyswip import core

        self.thread = threading.get_ident()
        lib = core._lib
        self.lib = lib
        # The foreign calls that only build or read terms take microseconds: they keep the
        # GIL (a PyDLL view of the same library). Only calls that run Prolog goals
        # (call_predicate, an open query's next solution) let other Python threads run —
        # the monitor's server, perception, the Ctrl-C watcher. A control step used to hand
        # the GIL over some twenty times, and a busy server thread took it each time.
        quick = ctypes.PyDLL(lib._name, handle=lib._handle)
        T = c_size_t  # term_t, atom_t, functor_t, fid_t are uintptr_t

        def fn(name: str, restype: Any, *argtypes: Any, runs_prolog: bool = False) -> Any:
            f = getattr(lib if runs_prolog else quick, name)
            f.restype = restype
            f.argtypes = list(argtypes)
            return f

        self.new_term_refs = fn("PL_new_term_refs", T, c_size_t)
        self.new_term_ref = fn("PL_new_term_ref", T)
        self.put_chars = fn("PL_put_chars", c_int, T, c_int, c_size_t, c_char_p)
        self.put_int64 = fn("PL_put_int64", c_int, T, c_int64)
        self.put_float = fn("PL_put_float", c_int, T, c_double)
        self.put_nil = fn("PL_put_nil", c_int, T)
        self.put_variable = fn("PL_put_variable", c_int, T)
        self.put_term = fn("PL_put_term", c_int, T, T)
        self.cons_list = fn("PL_cons_list", c_int, T, T, T)
        self.cons_functor_v = fn("PL_cons_functor_v", c_int, T, T, T)
        self.new_atom = fn("PL_new_atom_mbchars", T, c_int, c_size_t, c_char_p)
        self.put_atom = fn("PL_put_atom", c_int, T, T)
        self._atoms: dict[str, int] = {}
        self.new_functor = fn("PL_new_functor_sz", T, T, c_size_t)
        self.unregister_atom = fn("PL_unregister_atom", None, T)
        self.chars_to_term = fn("PL_chars_to_term", c_int, c_char_p, T)
        self.term_type = fn("PL_term_type", c_int, T)
        self.get_nchars = fn("PL_get_nchars", c_int, T, POINTER(c_size_t),
                             POINTER(c_char_p), c_uint)
        self.get_int64 = fn("PL_get_int64", c_int, T, POINTER(c_int64))
        self.get_float = fn("PL_get_float", c_int, T, POINTER(c_double))
        self.get_name_arity = fn("PL_get_name_arity_sz", c_int, T, POINTER(T), POINTER(c_size_t))
        self.atom_nchars = fn("PL_atom_mbchars", c_int, T, POINTER(c_size_t),
                              POINTER(c_char_p), c_uint)
        self.get_arg = fn("PL_get_arg_sz", c_int, c_size_t, T, T)
        self.get_atom = fn("PL_get_atom", c_int, T, POINTER(T))
        self.get_nil = fn("PL_get_nil", c_int, T)
        self.get_list = fn("PL_get_list", c_int, T, T, T)
        self.predicate = fn("PL_predicate", c_void_p, c_char_p, c_int, c_char_p)
        self.open_frame = fn("PL_open_foreign_frame", T)
        self.discard_frame = fn("PL_discard_foreign_frame", None, T)
        self.call_predicate = fn("PL_call_predicate", c_int, c_void_p, c_int, c_void_p, T,
                                 runs_prolog=True)
        self.exception = fn("PL_exception", T, T)
        self.clear_exception = fn("PL_clear_exception", None)
        self.record = fn("PL_record", c_void_p, T)
        self.recorded = fn("PL_recorded", c_int, c_void_p, T)
        self.erase = fn("PL_erase", None, c_void_p)
        self._records: dict[Any, int] = {}
        self._wants: dict[Any, int] = {}   # the step's lists of extras, apart from percepts
        self.thread_raise = fn("PL_thread_raise", c_int, c_int, c_int)
        self.prolog_thread = fn("PL_thread_self", c_int)()
        self.busy = False          # a goal of run() or of an open query is running
        self.mark_strings = fn("PL_mark_string_buffers", None, POINTER(c_size_t))
        self.release_strings = fn("PL_release_string_buffers_from_mark", None, c_size_t)

        self._functors: dict[tuple[str, int], int] = {}
        self._gw_run = self.predicate(b"gw_run", 3, b"relrl_gateway")
        self.calls = 0
        self._bootstrap()
        self._gw_step = self.predicate(b"gw_step", 15, b"relrl_gateway")
        # Reused out-parameters of the step's reads (one thread uses the engine).
        self._i64, self._f64, self._atom = c_int64(), c_double(), c_size_t()
        self._held: dict[int, str] = {}
        self._step_mark: int | None = None
        self._kernel: Any = None          # the compiled step: None untried, False none
        self._flatten: Any = None         # the compiled reader (loaded with the step's)
        self._held_names: dict[str, int] = {}
        self._true = self.hold("true")

    # -- Python -> Prolog ------------------------------------------------------------------

    def functor_t(self, name: str, arity: int) -> int:
        key = (name, arity)
        f = self._functors.get(key)
        if f is None:
            f = self.new_functor(self._new_atom(name), arity)
            self._functors[key] = f  # the functor keeps the atom alive
        return f

    def hold(self, name: str) -> int:
        """The handle of atom ``name``, referenced for the life of the process so that
        reads can name it without converting text (see :meth:`step`)."""
        atom = self._held_names.get(name)
        if atom is None:
            atom = self._new_atom(name)
            self._held_names[name] = atom
            self._held[atom] = name
        return atom

    def _new_atom(self, name: str) -> int:
        """A new reference to atom ``name`` (the caller keeps it)."""
        data = name.encode("utf-8")
        atom = self.new_atom(_REP_UTF8, len(data), data)
        if not atom:
            raise RelrlError(f"cannot make an atom of {name!r}")
        return atom

    def atom_of(self, name: str) -> int:
        """The handle of atom ``name`` (cached; the cache holds a reference)."""
        atom = self._atoms.get(name)
        if atom is None:
            atom = self._new_atom(name)
            if len(self._atoms) >= _MAX_ATOMS:   # keep the cache (and what it holds) small
                for old in self._atoms.values():
                    self.unregister_atom(old)
                self._atoms.clear()
            self._atoms[name] = atom          # the reference keeps the atom alive
        return atom

    def record_of(self, value: Cached, table: dict[Any, int] | None = None) -> int:
        """The handle of ``value``'s record in ``table`` (the percepts' by default; made on
        first use, see :class:`Cached`). A later record of the same table may evict it:
        use it before making another."""
        table = self._records if table is None else table
        rec = table.get(value.key)
        if rec is None:
            fid = self.open_frame()
            try:
                t = self.new_term_ref()
                self.put(t, value.value, {})
                rec = self._keep_record(value.key, t, table)
            finally:
                self.discard_frame(fid)
        return rec

    def _keep_record(self, key: Any, t: int, table: dict[Any, int] | None = None) -> int:
        table = self._records if table is None else table
        if len(table) >= _MAX_RECORDS:     # keep the table (and what it holds) small
            for old in table.values():
                self.erase(old)
            table.clear()
        rec = table[key] = self.record(t)
        return rec

    def put(self, t: int, value: Term, variables: dict[int, int]) -> None:
        """Write ``value`` into term reference ``t``."""
        if isinstance(value, str):
            self.put_atom(t, self.atom_of(value))
        elif isinstance(value, bool):
            self.put_chars(t, _PL_ATOM, 4 if value else 5, b"true" if value else b"false")
        elif isinstance(value, int):
            if -(2**63) <= value < 2**63:
                self.put_int64(t, value)
            else:
                self.chars_to_term(str(value).encode(), t)
        elif isinstance(value, float):
            self.put_float(t, value)
        elif isinstance(value, tuple):
            if not value or not isinstance(value[0], str):
                raise TypeError(f"a compound term is (name, args...), not {value!r}")
            if len(value) == 1:
                self.put(t, value[0], variables)
                return
            n = len(value) - 1
            a0 = self.new_term_refs(n)
            for i, arg in enumerate(value[1:]):
                self.put(a0 + i, arg, variables)
            self.cons_functor_v(t, self.functor_t(value[0], n), a0)
        elif isinstance(value, list):
            self.put_nil(t)
            if value:
                head = self.new_term_ref()
                for item in reversed(value):
                    self.put(head, item, variables)
                    self.cons_list(t, head, t)
        elif isinstance(value, Cached):
            rec = self._records.get(value.key)
            if rec is None:
                self.put(t, value.value, variables)
                self._keep_record(value.key, t)
            else:
                self.recorded(rec, t)
        elif isinstance(value, Var):
            known = variables.get(id(value))
            if known is None:
                self.put_variable(t)
                variables[id(value)] = t
            else:
                self.put_term(t, known)
        elif hasattr(value, "item") and callable(value.item):  # numpy scalar
            self.put(t, value.item(), variables)
        else:
            raise TypeError(f"cannot pass {type(value).__name__} {value!r} to Prolog")

    # -- Prolog -> Python ------------------------------------------------------------------

    def _text(self, t: int, flags: int) -> str:
        n = c_size_t()
        s = c_char_p()
        if not self.get_nchars(t, byref(n), byref(s), flags | _BUF_DISCARDABLE | _REP_UTF8):
            raise RelrlError("cannot read text from a Prolog term")
        return ctypes.string_at(s, n.value).decode("utf-8")

    def _atom_name(self, atom: int) -> str:
        name = self._held.get(atom)
        if name is None:
            n = c_size_t()
            s = c_char_p()
            self.atom_nchars(atom, byref(n), byref(s), _REP_UTF8)
            name = ctypes.string_at(s, n.value).decode("utf-8")
        return name

    def get(self, t: int) -> Term:
        """Read the term at reference ``t`` as a Python value.

        A compound or a list is read in one compiled call (:mod:`relrl._read_kernel`)
        once the compiled calls are loaded — with the first control step: a process that
        never steps (``relrl check``, a shell) does not pay numba's half second of
        loading —, else node by node, as an atom or a number always is.

        Raises:
            PrologError: the term is nested deeper than :data:`MAX_DEPTH` (or cyclic), or
                holds a list longer than :data:`MAX_LIST` (or cyclic).
        """
        flatten = self._flatten
        if not flatten:
            return self._get_nodes(t)
        kind = self.term_type(t)
        if kind != _PL_TERM and kind != _PL_LIST_PAIR:
            return self._get_nodes(t, 0, kind)
        ops, nums, text, stack = self._read_arrays
        while True:
            n = flatten(t, ops, nums, text, stack, MAX_DEPTH, MAX_LIST)
            if n != _FULL:
                break
            ops, nums, text, stack = self._read_arrays = tuple(
                _grown(a) for a in self._read_arrays)
        if n == _DEEP:
            raise _too_deep()
        if n == _LONG:
            raise _too_long()
        return self._decode(ops[:n].tolist(), nums, text)

    def _decode(self, ops: list[int], nums: Any, text: Any) -> Term:
        """The value of a stream written by :func:`relrl._read_kernel.flatten`."""
        names: dict[int, str] = {}
        stack: list[list[Any]] = [[[], 1, _R_ROOT]]
        i = 0
        while True:
            op = ops[i]
            if op == _R_ATOM:
                handle = ops[i + 1]
                value = names.get(handle)
                if value is None:
                    value = names[handle] = self._atom_name(handle)
                i += 2
            elif op == _R_TERM:
                handle, arity = ops[i + 1], ops[i + 2]
                name = names.get(handle)
                if name is None:
                    name = names[handle] = self._atom_name(handle)
                i += 3
                if arity:
                    stack.append([[name], arity, _R_TERM])
                    continue
                value = (name,)
            elif op == _R_INT:
                value = ops[i + 1]
                i += 2
            elif op == _R_FLOAT:
                value = float(nums[ops[i + 1]])
                i += 2
            elif op == _R_STRING:
                start = ops[i + 1]
                value = text[start:start + ops[i + 2]].tobytes().decode("utf-8")
                i += 3
            elif op == _R_NIL:
                value = []
                i += 1
            elif op == _R_LIST:
                stack.append([[], ops[i + 1] + 1, _R_LIST])      # the elements, the tail
                i += 2
                continue
            else:
                value = self._get_nodes(ops[i + 1])
                i += 2
            while True:                       # the value completes its container(s)
                top = stack[-1]
                top[0].append(value)
                top[1] -= 1
                if top[1]:
                    break
                stack.pop()
                items = top[0]
                if top[2] == _R_TERM:
                    value = tuple(items)
                elif top[2] == _R_LIST:
                    value = items
                    tail = items.pop()
                    if not (type(tail) is list and not tail):
                        value = tail          # [a, b|T]: the '[|]' compounds it is made of
                        for item in reversed(items):
                            value = ("[|]", item, value)
                else:
                    return value

    def _get_nodes(self, t: int, depth: int = 0, kind: int = 0) -> Term:
        """:meth:`get` node by node (a foreign call or more per node); ``kind``: the
        term's type when known."""
        if depth > MAX_DEPTH:
            raise _too_deep()
        kind = kind or self.term_type(t)
        if kind == _PL_ATOM:
            return self._text(t, _CVT_ATOM)
        if kind == _PL_INTEGER:
            v = c_int64()
            if self.get_int64(t, byref(v)):
                return v.value
            return int(self._text(t, _CVT_INTEGER))
        if kind == _PL_FLOAT:
            d = c_double()
            self.get_float(t, byref(d))
            return d.value
        if kind == _PL_STRING:
            return self._text(t, _CVT_STRING)
        if kind == _PL_NIL:
            return []
        if kind == _PL_LIST_PAIR:
            items = []
            head = self.new_term_ref()
            rest = self.new_term_ref()
            self.put_term(rest, t)
            n = 0
            while self.get_list(rest, head, rest):
                items.append(self._get_nodes(head, depth + 1))
                n += 1
                if n > MAX_LIST:
                    raise _too_long()
            if self.term_type(rest) != _PL_NIL:
                # A partial list [a, b|T]: as the '[|]' compounds it is made of.
                value: Term = self._get_nodes(rest, depth + 1)
                for item in reversed(items):
                    value = ("[|]", item, value)
                return value
            return items
        if kind == _PL_TERM:
            name = c_size_t()
            arity = c_size_t()
            self.get_name_arity(t, byref(name), byref(arity))
            arg = self.new_term_ref()
            values = [self._atom_name(name.value)]
            for i in range(1, arity.value + 1):
                self.get_arg(i, t, arg)
                values.append(self._get_nodes(arg, depth + 1))
            return tuple(values)
        if kind == _PL_VARIABLE:
            return Var(self._text(t, _CVT_VARIABLE))
        if kind == _PL_RATIONAL:
            from fractions import Fraction

            return Fraction(self._text(t, _CVT_WRITEQ).replace("r", "/"))   # 1r3
        return self._text(t, _CVT_WRITEQ)

    # -- running goals ---------------------------------------------------------------------

    def run(self, goal: Term, timeout: float, outputs: Sequence[int] = ()) -> list | None:
        """Run ``goal`` once; return the values of the argument positions in ``outputs``.

        Returns None when the goal fails. Raises QueryTimeout or PrologError.
        """
        if threading.get_ident() != self.thread:
            raise RelrlError("the Prolog engine belongs to the thread that started it; "
                             "use processes, not threads, for parallel runs")
        # Text conversions push buffers on SWI-Prolog's string stack, which is only popped
        # when a foreign predicate returns: a host calling in a million times must pop them
        # itself, or Prolog dies with "Too many stacked strings".
        mark = c_size_t()
        self.mark_strings(byref(mark))
        fid = self.open_frame()
        try:
            self.calls += 1
            a0 = self.new_term_refs(3)
            variables: dict[int, int] = {}
            self.put(a0, goal, variables)
            self.put_float(a0 + 1, float(timeout or 0))
            self.put_variable(a0 + 2)
            self.busy = True
            try:
                ok = self.call_predicate(None, _PL_Q_NODEBUG | _PL_Q_CATCH_EXCEPTION,
                                         self._gw_run, a0)
            finally:
                self.busy = False
            if not ok:
                self._raise_exception()
            result = self.get(a0 + 2)
            if result == "false":
                return None
            if result != "true":
                _raise_result(result, timeout)
            if not outputs:
                return []
            # goal is Module:Goal or Goal; read the requested arguments of Goal.
            inner = self.new_term_ref()
            self.put_term(inner, a0)
            if isinstance(goal, tuple) and goal[0] == ":" and len(goal) == 3:
                self.get_arg(2, a0, inner)
            arg = self.new_term_ref()
            values = []
            for i in outputs:
                self.get_arg(i + 1, inner, arg)
                values.append(self.get(arg))
            return values
        finally:
            self.discard_frame(fid)
            self.release_strings(mark.value)

    def step(self, module: str, percepts: Term, emitted: int, mode: str, want: list[str],
             timeout: float) -> tuple | None:
        """One control step through ``relrl_gateway:gw_step/15`` (the gateway's
        ``engine_step/6`` under the same time limit and error handling as :meth:`run`).

        The result's fields come back as arguments of their own and are read with one
        foreign call each, not as a term converted node by node: the robot steps thousands
        of times a second. With numba the whole crossing — arguments, call, reads — is one
        compiled call (:mod:`relrl._step_kernel`); without it, or for a field the kernel
        cannot read, the same foreign calls go through ctypes. Returns ``(code, necessity,
        outputs, reward, reinforced, mask, action, extras)`` (``extras`` None when empty),
        or None when the step failed. Raises QueryTimeout or PrologError as :meth:`run`
        does.
        """
        if threading.get_ident() != self.thread:
            raise RelrlError("the Prolog engine belongs to the thread that started it; "
                             "use processes, not threads, for parallel runs")
        self.calls += 1
        kernel = self._kernel if self._kernel is not None else self._load_kernel()
        if kernel and type(percepts) is Cached:
            return self._kernel_step(kernel, module, percepts, emitted, mode, want, timeout)
        fid = self.open_frame()
        try:
            a = self.new_term_refs(15)     # fresh variables
            self.put_atom(a, self.atom_of(module))
            self.put(a + 1, percepts, {})
            self.put_int64(a + 2, emitted)
            self.put_atom(a + 3, self.atom_of(mode))
            if want:
                self.put(a + 4, want, {})
            else:
                self.put_nil(a + 4)
            self.put_float(a + 5, timeout)
            ok = self.call_predicate(None, _PL_Q_NODEBUG | _PL_Q_CATCH_EXCEPTION,
                                     self._gw_step, a)
            return self._step_read(a, ok, want, timeout)
        finally:
            self.discard_frame(fid)
            if self._step_mark is not None:
                self.release_strings(self._step_mark)
                self._step_mark = None

    def _kernel_step(self, kernel: Any, module: str, percepts: Cached, emitted: int,
                     mode: str, want: list[str], timeout: float) -> tuple | None:
        """:meth:`step` as one compiled call; what the kernel does not read (see
        :mod:`relrl._step_kernel`) is read by :meth:`_step_read` from the open frame."""
        k, io, fo = self._k, self._io, self._fo
        io[k.MODULE] = self.atom_of(module)
        io[k.MODE] = self.atom_of(mode)
        io[k.PERCEPTS] = self.record_of(percepts)
        io[k.WANT] = self.record_of(Cached(want), self._wants) if want else 0
        io[k.EMITTED] = emitted
        fo[k.LIMIT] = timeout
        io[k.FRAME] = 0
        try:
            status = kernel(io, fo)
            v = io.tolist()
            if status == 0:
                necessity = self._held.get(v[k.NECESSITY])
                if necessity is not None:
                    n = v[k.OUTPUTS]
                    values = fo[:k.FIRST_OUTPUT + n].tolist()
                    extras = self._step_field(v[k.ARGS] + 14) if v[k.EXTRAS] else None
                    return (v[k.CODE], necessity, values[k.FIRST_OUTPUT:],
                            values[k.REWARD], v[k.REINFORCED] == self._true, v[k.MASK],
                            v[k.ACTION], extras)
            return self._step_read(v[k.ARGS], status != k.RAISED, want, timeout)
        finally:
            # (read from io: a KeyboardInterrupt may come as soon as the kernel returns)
            if io[k.FRAME]:
                self.discard_frame(int(io[k.FRAME]))
                io[k.FRAME] = 0
            if self._step_mark is not None:
                self.release_strings(self._step_mark)
                self._step_mark = None

    def _load_kernel(self) -> Any:
        """The compiled step (:mod:`relrl._step_kernel`), or False without numba or with
        ``RELRL_KERNELS=0`` in the environment (the ctypes calls do the same); loads the
        compiled reader (:mod:`relrl._read_kernel`) beside it. Loads once."""
        if self._kernel is not None:
            return self._kernel
        self._kernel = self._flatten = False
        if os.environ.get("RELRL_KERNELS", "1") == "0":
            return False
        try:
            import llvmlite.binding
            import numpy as np

            llvmlite.binding.load_library_permanently(self.lib._name)
            from relrl import _read_kernel as r
            from relrl import _step_kernel as k
        except ImportError:      # pragma: no cover - numba is a dependency
            return False
        self._flatten = r.flatten
        self._read_arrays = (np.zeros(4096, np.int64), np.zeros(512, np.float64),
                             np.zeros(16384, np.uint8), np.zeros((256, 4), np.int64))
        self._k = k
        self._io = np.zeros(k.IO_SIZE, np.int64)
        self._fo = np.zeros(k.FIRST_OUTPUT + 64, np.float64)
        self._io[k.PRED] = self._gw_step
        self._io[k.FLAGS] = _PL_Q_NODEBUG | _PL_Q_CATCH_EXCEPTION
        self._io[k.TRUE] = self._true
        self._kernel = k.step
        return self._kernel

    def _step_read(self, a: int, ok: bool, want: list[str], timeout: float) -> tuple | None:
        """The fields of a ``gw_step/15`` call at argument references ``a``..``a+14``
        (``ok``: the call returned), read with one foreign call each where they fit."""
        if not ok:
            return self._step_failed(timeout, None)
        atom, i64, f64 = self._atom, self._i64, self._f64
        get_atom, get_int64, get_float = self.get_atom, self.get_int64, self.get_float
        held = self._held
        # No text is converted on this path (atoms are read by handle): any field that
        # does not fit its one-call read goes to _step_field, which marks the string
        # stack first (see run()).
        if not (get_atom(a + 6, atom) and atom.value == self._true):
            return self._step_failed(timeout, a + 6)
        code = i64.value if get_int64(a + 7, i64) else self._step_field(a + 7)
        necessity = held.get(atom.value) if get_atom(a + 8, atom) else None
        if necessity is None:
            necessity = self._step_field(a + 8)
        outputs = []
        head, rest = self.new_term_ref(), self.new_term_ref()
        self.put_term(rest, a + 9)
        while self.get_list(rest, head, rest):
            outputs.append(f64.value if get_float(head, f64) else self._step_field(head))
        reward = f64.value if get_float(a + 10, f64) else self._step_field(a + 10)
        reinforced = get_atom(a + 11, atom) and atom.value == self._true
        mask = i64.value if get_int64(a + 12, i64) else self._step_field(a + 12)
        action = i64.value if get_int64(a + 13, i64) else self._step_field(a + 13)
        extras = self._step_field(a + 14) if want and not self.get_nil(a + 14) else None
        return code, necessity, outputs, reward, bool(reinforced), mask, action, extras

    def _step_field(self, t: int) -> Term:
        """A field of a step's result read by conversion (after marking the string
        stack once; :meth:`step` releases it)."""
        self._mark_step()
        return self.get(t)

    def _mark_step(self) -> None:
        """Mark the string stack once in a step (released when the step ends)."""
        if self._step_mark is None:
            self._step_mark = self._mark()

    def _step_failed(self, timeout: float, result: int | None) -> None:
        """The step's call raised (``result`` None) or gave ``false``/an error term at
        ``result``: None for false, else the exception."""
        if result is not None:
            value = self._step_field(result)
            if value == "false":
                return None
            _raise_result(value, timeout)
        self._mark_step()
        self._raise_exception()

    def _raise_exception(self) -> NoReturn:
        """The error for a gateway call that raised past its own catch (the string stack
        already marked)."""
        ex = self.exception(0)
        if not ex:
            # abort/0 unwinds past every catch/3: gw_run/3 noted where it came from.
            self.clear_exception()
            raise self._aborted()
        detail = self.get(ex)
        self.clear_exception()
        raise PrologError(f"gateway call failed: {detail!r}", detail)

    def _mark(self) -> int:
        """Mark the string stack (see :meth:`run`); release with ``release_strings``."""
        mark = c_size_t()
        self.mark_strings(byref(mark))
        return mark.value

    @contextlib.contextmanager
    def interruptible(self) -> Iterator[None]:
        """Within the block, Ctrl-C (SIGINT) stops the Prolog goal running at that moment
        (a user's query), as at swipl's toplevel, instead of when its time limit strikes.

        Python only sees a signal between bytecodes, not while Prolog runs: the signal's
        byte arrives on a wakeup pipe (:func:`signal.set_wakeup_fd`) that a thread
        watches; while a goal runs, the thread raises SIGUSR1 in Prolog's thread
        (``PL_thread_raise``, safe from any thread), whose handler in gateway.pl throws
        inside the goal. The goal ends with an error the gateway reports, and Python's own
        KeyboardInterrupt follows. Outside the main thread this does nothing.
        """
        if threading.current_thread() is not threading.main_thread() \
                or threading.get_ident() != self.thread:
            yield
            return
        r, w = os.pipe()
        os.set_blocking(w, False)
        old = signal.set_wakeup_fd(w, warn_on_full_buffer=False)

        def watch() -> None:
            while data := os.read(r, 512):        # b"" once the write end is closed
                if signal.SIGINT in data and self.busy:
                    self.thread_raise(self.prolog_thread, signal.SIGUSR1)

        watcher = threading.Thread(target=watch, name="relrl-interrupts", daemon=True)
        watcher.start()
        try:
            yield
        finally:
            signal.set_wakeup_fd(old)
            os.close(w)
            watcher.join(5)
            os.close(r)

    def _aborted(self) -> RelrlError:
        """The error for a goal that called abort/0 (asks gw_take_abort/1 where)."""
        out = self.run((":", "relrl_gateway", ("gw_take_abort", Var())), 0, (0,))
        where = out[0] if out else "goal"
        if isinstance(where, tuple) and where[0] == ":":
            return Aborted(str(where[1]), where[2] or None)
        return Aborted(None, None)

    def _bootstrap(self) -> None:
        gateway = PROLOG_DIR / "gateway.pl"
        if not gateway.exists():
            raise RelrlError(f"relrl's Prolog files are missing: {gateway} "
                             "(set RELRL_PROLOG_DIR to the prolog/ folder)")
        fid = self.open_frame()
        try:
            t = self.new_term_ref()
            # A runaway recursion in a rule must end soon: 512 MB of stack (SWI-Prolog's
            # default is 1 GB) overflows in about 1.5 s here instead of 3.
            self.put(t, (",", ("set_prolog_flag", "stack_limit", STACK_LIMIT),
                         ("use_module", str(gateway))), {})
            pred = self.predicate(b"call", 1, b"user")
            if not self.call_predicate(None, _PL_Q_NODEBUG | _PL_Q_CATCH_EXCEPTION, pred, t):
                raise RelrlError(f"cannot load {gateway}")
        finally:
            self.discard_frame(fid)
        self._gw_run = self.predicate(b"gw_run", 3, b"relrl_gateway")


class Aborted(RuleError):
    """A loaded file or a rule called abort/0."""

    def __init__(self, path: str | None, line: int | None) -> None:
        where = f"{_display_path(path)}:{line}" if path and line else (
            _display_path(path) if path else None)
        text = "abort/0 called" + (" while loading" if path else " by a goal")
        super().__init__(f"{where}: {text}" if where else text, "abort", where)
        self.path = path
        self.line = line


def _raise_result(result: Term, timeout: float) -> None:
    """Turn an error(E, Message) result of gw_run/3 into a Python exception."""
    if isinstance(result, tuple) and result[0] == "error":
        error, message = result[1], result[2]
        message = _KB_MODULE.sub("", str(message))
        kind = error[0] if isinstance(error, tuple) else error
        if kind == "time_limit_exceeded":
            if isinstance(error, tuple):  # time_limit_exceeded(rule(Goal, Where))
                _, (_, rule, where) = error
                raise QueryTimeout(f"{_where(where)}: rule {_KB_MODULE.sub('', rule)} ran longer "
                                   f"than {timeout:g} s (a rule that never ends?)", rule, where)
            raise QueryTimeout(f"query ran longer than {timeout:g} s (a rule that never ends?)")
        if kind == "rule_error":
            _, rule, where, formal = error
            raise RuleError(message.replace(str(where), _where(where), 1),
                            _KB_MODULE.sub("", rule), _where(where), formal)
        if kind == "policy_error":
            raise PolicyError(message.replace(str(error[1]), _display_path(str(error[1])), 1))
        if kind == "halt_called":
            raise RuleError(message, "halt", None, error)
        if kind == "aborted":
            raise Aborted(None, None)
        if kind == "interrupted":
            raise KeyboardInterrupt
        raise PrologError(message, error)
    raise PrologError(f"unexpected gateway result {result!r}", result)


def _where(where: str) -> str:
    """``file:line`` with the file shown relative to the working directory."""
    path, sep, line = str(where).rpartition(":")
    return f"{_display_path(path)}:{line}" if sep and path else str(where)


_engine: _Engine | None = None
_engine_lock = threading.Lock()


def _get_engine() -> _Engine:
    global _engine
    if _engine is None:
        with _engine_lock:
            if _engine is None:
                _engine = _Engine()
    return _engine


def gateway_calls() -> int:
    """Number of calls into Prolog made through the gateway so far in this process."""
    return _engine.calls if _engine is not None else 0


class KnowledgeBase:
    """A knowledge base: one Prolog module holding a domain and its working memory.

    Example:
        >>> kb = KnowledgeBase("examples/domains/fruits.pl")
        >>> kb.insert([("see", "face"), ("pose", "face", "frontal")])
        >>> kb.holds(("see", ("frontal", "face")))
        True

    Args:
        *domains: domain files to load, in order.
        timeout: seconds any one call may run before raising QueryTimeout.
        strict: treat load warnings (singleton variables, discontiguous clauses) as errors.
    """

    def __init__(self, *domains: str | os.PathLike, timeout: float = DEFAULT_TIMEOUT,
                 strict: bool = True) -> None:
        self._engine = _get_engine()
        self.timeout = timeout
        self.files: list[Path] = []
        self.warnings: list[Problem] = []
        out = self._engine.run((":", "relrl_gateway", ("gw_new_kb", Var())), timeout, (0,))
        self.module: str = out[0]  # type: ignore[index]
        self._closed = False
        for path in domains:
            self.load(path, strict=strict)

    # -- loading ---------------------------------------------------------------------------

    def load(self, path: str | os.PathLike, *, strict: bool = True) -> list[Problem]:
        """Consult a domain (or policy) file into this knowledge base.

        Returns the warnings when ``strict`` is False.

        Raises:
            PrologLoadError: the file is missing, has a syntax error or another load error,
                or (when ``strict``) a warning; the message names file and line.
        """
        p = Path(path)
        try:
            out = self._engine.run((":", "relrl_gateway",
                                    ("gw_load", str(p), self.module, float(self.timeout),
                                     Var())), 0, (3,))
        except Aborted as exc:
            raise PrologLoadError(_display_path(str(p)), None,
                                  "abort/0 called while loading") from exc
        problems = [Problem(kind, str(f) if f else str(p), line or None, msg)
                    for (_, kind, f, line, msg) in out[0]]  # type: ignore[index]
        problems = [Problem(pr.kind, _display_path(pr.path), pr.line,
                            _KB_MODULE.sub("", pr.message)) for pr in problems]
        errors = [pr for pr in problems if pr.kind == "error" or strict]
        if errors:
            first = errors[0]
            raise PrologLoadError(first.path, first.line, first.message,
                                  [(e.path, e.line, f"{e.kind}: {e.message}")
                                   for e in problems])
        self.files.append(p)
        self.warnings.extend(problems)
        return problems

    # -- running goals ---------------------------------------------------------------------

    def call(self, predicate: str, *arguments: Term, timeout: float | None = None) -> list | None:
        """Call ``module:name(arguments...)`` once; return the values of its :class:`Var`
        arguments in order, or None when it fails.

        ``predicate`` is ``"module:name"`` or ``"name"`` (run in this knowledge base).
        """
        module, _, name = predicate.rpartition(":")
        goal: Term = (name, *arguments) if arguments else name
        goal = (":", module or self.module, goal)
        outputs = [i for i, a in enumerate(arguments) if isinstance(a, Var)]
        return self._engine.run(goal, self.timeout if timeout is None else timeout, outputs)

    def step(self, percepts: Term, emitted: int, mode: str, want: list[str]) -> tuple | None:
        """The control step of this knowledge base's engine in one gateway call (see
        :class:`relrl.engine.Engine`, which decodes it); None when the step failed."""
        return self._engine.step(self.module, percepts, emitted, mode, want,
                                 float(self.timeout or 0))

    def interruptible(self) -> contextlib.AbstractContextManager[None]:
        """A context in which Ctrl-C stops the running goal at once (see
        :meth:`_Engine.interruptible`); for a user's queries at a terminal."""
        return self._engine.interruptible()

    def hold(self, names: Iterable[str]) -> None:
        """Keep the atoms ``names`` (necessities, ...) so that the step reads them by
        handle."""
        for name in names:
            self._engine.hold(name)

    def holds(self, goal: Term, *, timeout: float | None = None) -> bool:
        """True when ``goal`` (a term) succeeds in this knowledge base."""
        out = self._engine.run((":", self.module, goal),
                               self.timeout if timeout is None else timeout)
        return out is not None

    def query(self, text: str, *, max_solutions: int = 100,
              timeout: float | None = None) -> tuple[list[list[tuple[str, Term, str]]], bool]:
        """Run a query typed by a user (Prolog syntax, without the final full stop).

        Returns ``(solutions, more)``: each solution is a list of
        ``(variable name, value, value printed as Prolog)``; ``more`` is True when there
        were more than ``max_solutions``.

        Raises:
            PrologError: syntax error or exception in the query.
            QueryTimeout: the query ran longer than the time limit.
        """
        limit = self.timeout if timeout is None else timeout
        text = text.strip()
        if text.endswith("."):
            text = text[:-1]
        out = self._engine.run((":", "relrl_gateway",
                                ("gw_query", self.module, text, float(limit), max_solutions,
                                 Var())), 0, (4,))
        result = out[0]  # type: ignore[index]
        if result[0] == "error":
            _raise_result(result, limit)
        _, solutions, more = result
        return ([[(name, value, printed) for (_, (_, name, value), printed) in sol]
                 for sol in solutions], more == "true")

    def open_query(self, text: str, *, timeout: float | None = None,
                   mode: str = "print") -> Any:
        """Open a query typed by a user (Prolog syntax) to take its answers one at a time,
        as swipl's toplevel does (``relrl shell``). Close it, or use it as a context manager.

        Args:
            text: the query, with or without its final full stop.
            timeout: seconds each answer may take (the clock stops between answers);
                default: this knowledge base's time limit. It must be positive: a user's
                query is always bounded.
            mode: ``"print"`` writes terms to depth 10 (swipl's default), ``"write"`` whole.
        """
        from relrl.query import OpenQuery

        return OpenQuery(self, text, self.timeout if timeout is None else timeout, mode)

    # -- the knowledge layer ---------------------------------------------------------------

    # Each method below is one goal of the knowledge layer, named in relrl.engine.GOALS.

    def insert(self, elements: Iterable[Term]) -> None:
        """One insertion of ``elements`` into working memory (they get age 0)."""
        _engine_call(self, "wm_insert", self.module, list(elements))

    def memory(self) -> list[tuple[int, Term]]:
        """Working memory as ``(age, element)`` pairs, youngest first."""
        pairs = _engine_call(self, "wm_elements", self.module, Var())[0]
        return [(age, element) for (_, age, element) in pairs]

    def clear_memory(self) -> None:
        """Forget every element of working memory."""
        _engine_call(self, "wm_clear", self.module)

    def state_code(self) -> int:
        """The current state code: sum of 2^x over the stimuli and facts that hold now."""
        return _engine_call(self, "state_code", self.module, Var())[0]

    def state_terms(self) -> list[Term]:
        """The stimuli and facts that hold now, as ``("stimulus", S)`` / ``("fact", F)``."""
        return _engine_call(self, "state_terms", self.module, Var())[0]

    def decode_state(self, code: int) -> list[Term]:
        """The stimuli and facts whose bits are set in ``code``."""
        return _engine_call(self, "state_decode", self.module, code, Var())[0]

    def encode_state(self, terms: list[Term]) -> int:
        """The state code of ``terms`` (``("stimulus", S)`` / ``("fact", F)`` features)."""
        return _engine_call(self, "state_encode", self.module, terms, Var())[0]

    def features(self) -> list[Term]:
        """Every stimulus and fact in code order (position x has code 2^x)."""
        return _engine_call(self, "state_features", self.module, Var())[0]

    def allowed_responses(self) -> list[Term]:
        """The responses the constraint rules allow now, in declaration order."""
        return _engine_call(self, "allowed_responses", self.module, Var())[0]

    def declarations(self, kind: str) -> list[Term]:
        """All ``kind`` declarations (``stimulus``, ``fact``, ``response``, ``necessity``)."""
        return [t[1] for t in self.find(kind, Var("X"))]

    def find(self, name: str, *arguments: Term) -> list[Term]:
        """Every declaration ``name(arguments...)`` of the domain, as terms (a template with
        :class:`~relrl.terms.Var` arguments; nothing but the domain's own clauses is run)."""
        return _engine_call(self, "findall", self.module, (name, *arguments), Var())[0]

    # -- life cycle ------------------------------------------------------------------------

    def close(self) -> None:
        """Forget this knowledge base's clauses and memory. Safe to call twice."""
        if not self._closed:
            self._closed = True
            self._engine.run((":", "relrl_gateway", ("gw_drop_kb", self.module)), self.timeout)

    def __enter__(self) -> KnowledgeBase:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        files = ", ".join(str(f) for f in self.files)
        return f"KnowledgeBase({self.module}: {files})"


def _engine_call(kb: KnowledgeBase, goal: str, *arguments: Term) -> list:
    from relrl.engine import call

    return call(kb, goal, *arguments)


def _display_path(path: str) -> str:
    """Show a path relative to the working directory when it is below it."""
    try:
        return str(Path(path).resolve().relative_to(Path.cwd()))
    except ValueError:
        return path


def measure_call_cost(n: int = 2000) -> float:
    """Seconds per gateway call with one binding (``relrl_state:state_code``-sized work)."""
    kb = KnowledgeBase()
    try:
        from relrl.engine import GOALS

        goal = GOALS["wm_clock"]
        kb.call(goal, kb.module, Var())
        t0 = time.perf_counter()
        for _ in range(n):
            kb.call(goal, kb.module, Var())
        return (time.perf_counter() - t0) / n
    finally:
        kb.close()
