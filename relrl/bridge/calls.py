"""Calls into Prolog: a goal run once, the control step, a query kept open; their errors.

Every call goes through one predicate of ``prolog/gateway.pl`` under the guard (a Prolog
exception comes back as a result term, never unwinding into the host), under a time limit
(:mod:`relrl.bridge.deadline`), in a foreign frame discarded afterwards, and with the
string buffers it pushed popped. A result that is an error is raised as the relrl
exception that keeps its structure (:func:`check_result`): a rule that loops is a
:class:`~relrl.errors.QueryTimeout` naming it, an error in a rule a
:class:`~relrl.errors.RuleError` naming its file and line, and so on.

SWI-Prolog's engine belongs to the thread that started it: a call from another thread
raises. Parallel runs use processes.
"""

from __future__ import annotations

import re
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from ctypes import byref, c_size_t
from pathlib import Path
from typing import Any, NoReturn

from relrl.bridge import lib as L
from relrl.bridge.deadline import Watchdog
from relrl.bridge.marshal import Cached, Marshal
from relrl.errors import PolicyError, PrologError, QueryTimeout, RelrlError, RuleError
from relrl.resources import prolog_dir
from relrl.terms import Term, Var

__all__ = ["Prolog", "Query", "Aborted", "check_result", "display_path", "prolog",
           "strip_kb_module"]

_KB_MODULE = re.compile(r"\brelrl_kb_\d+:")


class Aborted(RuleError):
    """A loaded file or a rule called abort/0."""

    def __init__(self, path: str | None, line: int | None) -> None:
        where = f"{display_path(path)}:{line}" if path and line else (
            display_path(path) if path else None)
        text = "abort/0 called" + (" while loading" if path else " by a goal")
        super().__init__(f"{where}: {text}" if where else text, "abort", where)
        self.path = path
        self.line = line


class Prolog:
    """The process's Prolog: the started library, the term conversion, the watchdog, and
    the calls. Made once, by :func:`prolog`."""

    def __init__(self) -> None:
        gateway = prolog_dir() / "gateway.pl"
        if not gateway.exists():
            raise RelrlError(f"relrl's Prolog files are missing: {gateway} "
                             "(set RELRL_PROLOG_DIR to the prolog/ folder)")
        self.lib = lib = L.start(lambda lib: _load(lib, gateway))
        self.marshal = Marshal(lib)
        self.thread = lib.thread
        tid = lib.thread_self()
        self.watchdog = Watchdog(lambda sig: lib.thread_raise(tid, sig))
        self.calls = 0                   # calls into Prolog so far (relrl bench counts them)
        self._flush_pending = False
        self._gw_run = lib.predicate(b"gw_run", 2, b"relrl_gateway")
        self._true = lib.predicate(b"true", 0, b"system")
        self._kernel: Any = None         # the compiled step, loaded with the first step
        self._api: dict[str, tuple[str, str]] | None = None   # python_api/2, asked once
        self._wants: dict[Any, int] = {}  # records of the steps' lists of extras

    # -- the API -------------------------------------------------------------------------

    def goal(self, name: str) -> tuple[str, str]:
        """``(module, predicate)`` of the goal of relrl's Prolog that Python calls ``name``:
        ``prolog/gateway.pl``'s ``python_api/2``, the one list of them, asked once.

        Raises:
            RelrlError: relrl's Prolog declares no goal of that name.
        """
        if self._api is None:
            out = self.run((":", "relrl_gateway", ("gw_api", Var())), 0, (0,))
            self._api = {str(n): (str(m), str(p))
                         for (_, n, (_, m, (_, p, _))) in out[0]}  # type: ignore[index]
        try:
            return self._api[name]
        except KeyError:
            raise RelrlError(f"relrl's Prolog declares no goal {name!r} for Python "
                             "(python_api/2 in prolog/gateway.pl)") from None

    def api(self, name: str, *arguments: Term, timeout: float = 0.0) -> list | None:
        """Run the goal ``python_api/2`` names ``name`` with ``arguments`` once (see
        :meth:`run`): the values of its :class:`~relrl.terms.Var` arguments, in order, or
        None when it fails."""
        module, predicate = self.goal(name)
        return self.run((":", module, (predicate, *arguments)), timeout,
                        [i for i, a in enumerate(arguments) if isinstance(a, Var)])

    # -- a goal, once ----------------------------------------------------------------------

    def run(self, goal: Term, timeout: float, outputs: Sequence[int] = (), *,
            watched: bool = False) -> list | None:
        """Run ``goal`` (``Module:Goal``) once; return the values of the arguments of
        ``Goal`` at the positions ``outputs``, or None when it fails. ``watched``: the goal
        runs under ``relrl_guard:progress_watch/2``, which holds its time limit (the
        watchdog only ticks).

        Raises:
            QueryTimeout, RuleError, PrologError, ...: see :func:`check_result`.
        """
        lib, marshal = self.lib, self.marshal
        with self._crossing():
            lib.keep_c_stack_guard()
            fid = lib.open_foreign_frame()
            try:
                a0 = lib.new_term_refs(2)
                marshal.put(a0, goal, {})
                if not self._timed(timeout, lib.call_predicate, None, L.CALL_FLAGS,
                                   self._gw_run, a0, tick=watched):
                    self._raise_exception()
                result = marshal.get(a0 + 1)
                if result == "false":
                    return None
                check_result(result, timeout)
                inner, arg = lib.new_term_ref(), lib.new_term_ref()
                lib.put_term(inner, a0)
                if isinstance(goal, tuple) and goal[0] == ":" and len(goal) == 3:
                    lib.get_arg_sz(2, a0, inner)
                values = []
                for i in outputs:
                    lib.get_arg_sz(i + 1, inner, arg)
                    values.append(marshal.get(arg))
                return values
            finally:
                lib.discard_foreign_frame(fid)

    def _timed(self, timeout: float, call: Any, *args: Any, tick: bool = False) -> Any:
        """``call(*args)``, a foreign call that runs Prolog, under the time limit (``tick``:
        a watched call, see :meth:`run`)."""
        self.calls += 1
        watchdog = self.watchdog
        watchdog.arm(timeout, tick=tick)
        try:
            return call(*args)
        finally:
            self._flush_pending |= watchdog.disarm()

    @contextmanager
    def _crossing(self) -> Iterator[None]:
        """Within the block: calls from this thread only; the string buffers pushed are
        popped after it, and a signal raised as its last call returned is taken."""
        self._check_thread()
        mark = c_size_t()
        self.lib.mark_string_buffers(byref(mark))
        outer, self.marshal.mark = self.marshal.mark, mark
        try:
            yield
        finally:
            self.marshal.mark = outer
            self.lib.release_string_buffers_from_mark(mark.value)
            self._flush()

    def _flush(self) -> None:
        """Let Prolog take a signal raised as the last call returned, outside any call
        (the guard's handlers then do nothing)."""
        if self._flush_pending:
            self._flush_pending = False
            if not self.lib.call_predicate(None, L.CALL_FLAGS, self._true, 0):
                self.lib.clear_exception()

    def _check_thread(self) -> None:
        if threading.get_ident() != self.thread:
            raise RelrlError("the Prolog engine belongs to the thread that started it; "
                             "use processes, not threads, for parallel runs")

    def _raise_exception(self) -> NoReturn:
        """The error of a call that raised past the guard: abort/0 unwinds past it; nothing
        else should (a Ctrl-C or a time limit raised again while the guard's handler runs
        finds the guard down: prolog/guard.pl), but what does is named, never taken for an
        abort."""
        ex = self.lib.exception(0)
        detail = self.marshal.get(ex) if ex else None
        self.lib.clear_exception()
        if detail is None or detail == "$aborted":
            out = self.api("take_abort", Var())
            where = out[0] if out else "goal"
            if isinstance(where, tuple) and where[0] == ":":
                raise Aborted(str(where[1]), where[2] or None)
            if detail == "$aborted" or where != "none":
                raise Aborted(None, None)
        if detail == "relrl_interrupted":
            raise KeyboardInterrupt
        raise PrologError(f"gateway call failed: {detail!r}", detail)

    # -- the control step ------------------------------------------------------------------

    def step(self, module: str, percepts: Cached, emitted: int, mode: str, want: list[str],
             timeout: float) -> tuple | None:
        """One control step (``relrl_gateway:gw_step/14``) in one compiled call
        (:mod:`relrl.bridge.stepkernel`). Returns ``(code, necessity, outputs, reward,
        reinforced, mask, action, extras)`` (``extras`` None when empty), or None when the
        step failed.

        Raises:
            QueryTimeout, RuleError, PrologError, ...: as :meth:`run`.
        """
        self._check_thread()
        k, io, fo = self._kernel or self._load_kernel()
        marshal = self.marshal
        io[k.MODULE] = marshal.atom(module)
        io[k.MODE] = marshal.atom(mode)
        io[k.PERCEPTS] = marshal.record(percepts)
        io[k.WANT] = marshal.record(Cached(want), self._wants) if want else 0
        io[k.EMITTED] = emitted
        io[k.FRAME] = 0
        mark = None
        try:
            status = self._timed(timeout, k.step, io, fo)
            v = io.tolist()
            if status == k.DONE:
                necessity = marshal.held(v[k.NECESSITY])
                if necessity is None:             # not held (Engine holds the necessities)
                    mark = c_size_t()
                    self.lib.mark_string_buffers(byref(mark))
                    necessity = marshal.atom_name(v[k.NECESSITY])
                values = fo[:k.FIRST_OUTPUT + v[k.OUTPUTS]].tolist()
                return (v[k.CODE], necessity, values[k.FIRST_OUTPUT:], values[k.REWARD],
                        v[k.REINFORCED] == self._true_atom, v[k.MASK], v[k.ACTION], None)
            mark = c_size_t()
            self.lib.mark_string_buffers(byref(mark))
            if status == k.RAISED:
                self._raise_exception()
            return self._step_rest(v[k.ARGS], timeout)
        finally:
            if io[k.FRAME]:            # read from io: Ctrl-C may come as the kernel returns
                self.lib.discard_foreign_frame(int(io[k.FRAME]))
                io[k.FRAME] = 0
            if mark is not None:
                self.lib.release_string_buffers_from_mark(mark.value)
            self._flush()

    def _step_rest(self, a: int, timeout: float) -> tuple | None:
        """The step's result and fields read as terms from its arguments at ``a`` (their
        positions: :data:`relrl.bridge.stepkernel.STEP_ARGUMENTS`)."""
        k = self._kernel[0]
        get = self.marshal.get
        result = get(a + k.RESULT)
        if result == "false":
            return None
        check_result(result, timeout)
        code, necessity, outputs, reward, reinforced, mask, action, extras = (
            get(a + i) for i in range(*k.FIELDS))
        return (code, necessity, outputs, reward, reinforced == "true", mask, action,
                extras or None)

    def _load_kernel(self) -> tuple:
        """The compiled step and its arrays (numba is imported here, at a process's first
        step: a process that only loads and queries does not pay for it)."""
        import numpy as np

        from relrl.bridge import stepkernel as k

        k.load(self.lib.path)
        io = np.zeros(k.IO_SIZE, np.int64)
        fo = np.zeros(k.FIRST_OUTPUT + 64, np.float64)
        io[k.PRED] = self.lib.predicate(b"gw_step", k.ARITY, b"relrl_gateway")
        io[k.FLAGS] = L.CALL_FLAGS
        io[k.TRUE] = self._true_atom = self.marshal.hold("true")
        self._kernel = (k, io, fo)
        return self._kernel

    # -- a query kept open -----------------------------------------------------------------

    def open(self, predicate: tuple[str, str], arguments: Sequence[Term]) -> Query:
        """Open ``module:name(arguments..., Answer)`` to take its answers one at a time."""
        self._check_thread()
        return Query(self, predicate, arguments)


class Query:
    """A goal kept open between its solutions (``PL_open_query``); each solution is sought
    under the time limit given to :meth:`next`, the clock stopped between them. Close it,
    or use it as a context manager. Other calls may run while it is open."""

    def __init__(self, prolog: Prolog, predicate: tuple[str, str],
                 arguments: Sequence[Term]) -> None:
        module, name = predicate
        lib = self._lib = prolog.lib
        lib.keep_c_stack_guard()
        self._prolog = prolog
        self._fid = lib.open_foreign_frame()
        n = len(arguments) + 1
        self._args = lib.new_term_refs(n)
        for i, value in enumerate(arguments):
            prolog.marshal.put(self._args + i, value, {})
        self._answer = self._args + n - 1
        pred = lib.predicate(name.encode(), n, module.encode())
        prolog.calls += 1
        self._qid: int | None = lib.open_query(None, L.Q_FLAGS, pred, self._args)

    @property
    def closed(self) -> bool:
        """True once the query has no more solutions or was closed."""
        return self._qid is None

    def next(self, timeout: float) -> Term | None:
        """The answer argument at the next solution, or None when there is none (the query
        is then closed).

        Raises:
            PrologError: the goal raised past its own catch (the query is then closed).
        """
        if self._qid is None:
            return None
        prolog, lib = self._prolog, self._lib
        with prolog._crossing():
            if prolog._timed(timeout, lib.next_solution, self._qid):
                return prolog.marshal.get(self._answer)
            ex = lib.exception(self._qid)
            detail = prolog.marshal.get(ex) if ex else None
            self.close()
            if detail == "$aborted":
                raise Aborted(None, None)
            if detail is not None:
                raise PrologError(f"query failed: {detail!r}", detail)
            return None

    def close(self) -> None:
        """Discard the query and its remaining solutions. Safe to call twice."""
        if self._qid is not None:
            qid, self._qid = self._qid, None
            self._lib.close_query(qid)
            self._lib.discard_foreign_frame(self._fid)

    def __enter__(self) -> Query:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _load(lib: L.Lib, gateway: Path) -> None:
    """Load relrl's gateway (and so its knowledge layer) into the started Prolog."""
    fid = lib.open_foreign_frame()
    try:
        t = lib.new_term_ref()
        text = f"use_module({_quoted(str(gateway))})".encode()
        if not (lib.chars_to_term(text, t) and lib.call_predicate(
                None, L.CALL_FLAGS, lib.predicate(b"call", 1, b"user"), t)):
            raise RelrlError(f"cannot load {gateway}")
    finally:
        lib.discard_foreign_frame(fid)


def _quoted(text: str) -> str:
    return "'" + text.replace("\\", "\\\\").replace("'", "\\'") + "'"


_prolog: Prolog | None = None
_prolog_lock = threading.Lock()


def prolog() -> Prolog:
    """The process's Prolog, started on first use."""
    global _prolog
    if _prolog is None:
        with _prolog_lock:
            if _prolog is None:
                _prolog = Prolog()
    return _prolog


# -- errors ----------------------------------------------------------------------------------

def check_result(result: Term, timeout: float) -> None:
    """Raise the relrl exception for a result of the guard that is not ``true``."""
    if result == "true":
        return
    if not (isinstance(result, tuple) and result[0] == "error"):
        raise PrologError(f"unexpected gateway result {result!r}", result)
    error, message = result[1], _KB_MODULE.sub("", str(result[2]))
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
        raise PolicyError(message.replace(str(error[1]), display_path(str(error[1])), 1))
    if kind == "halt_called":
        raise RuleError(message, "halt", None, error)
    if kind == "aborted":
        raise Aborted(None, None)
    if kind == "interrupted":
        raise KeyboardInterrupt
    raise PrologError(message, error)


def strip_kb_module(text: str) -> str:
    """``text`` without the knowledge bases' internal module names (``relrl_kb_3:``)."""
    return _KB_MODULE.sub("", text)


def _where(where: str) -> str:
    """``file:line`` with the file shown relative to the working directory."""
    path, sep, line = str(where).rpartition(":")
    return f"{display_path(path)}:{line}" if sep and path else str(where)


def display_path(path: str) -> str:
    """``path`` relative to the working directory when it is below it."""
    try:
        return str(Path(path).resolve().relative_to(Path.cwd()))
    except ValueError:
        return path

