"""A user's query, one answer at a time (``relrl shell``): part of the gateway.

This module extends :mod:`relrl.kb`, the one transport to Prolog: it keeps a query open in
Prolog between its answers (PL_open_query / PL_next_solution / PL_close_query) through the
process's one engine, and imports nothing of pyswip itself.
"""

from __future__ import annotations

import threading
from ctypes import byref, c_int, c_size_t, c_void_p
from dataclasses import dataclass
from typing import Any

from relrl.errors import ConfigError, PrologError, RelrlError
from relrl.kb import (
    _PL_Q_CATCH_EXCEPTION,
    _PL_Q_NODEBUG,
    Aborted,
    KnowledgeBase,
    _raise_result,
)

__all__ = ["Answer", "OpenQuery"]


@dataclass(frozen=True)
class Answer:
    """One answer of an :class:`OpenQuery`.

    Attributes:
        text: the bindings as swipl's toplevel writes them (cycles factorized, deep terms
            written to depth 10 unless asked otherwise), ``""`` when there are none.
        last: no further answer can follow (the goal left no choice point).
    """

    text: str
    last: bool


class OpenQuery:
    """A user's query kept open between its answers (see :meth:`KnowledgeBase.open_query`).

    Prolog keeps the query (PL_open_query/PL_next_solution/PL_close_query): each
    :meth:`next` resumes it for one more answer under the time limit, so output the goal
    writes comes out in order with the answers and an endless generator costs nothing until
    asked. Answers are written by Prolog's own writer; no term crosses the bridge. Only one
    query is open at a time; other gateway calls may run while it is open.
    """

    def __init__(self, kb: KnowledgeBase, text: str, timeout: float,
                 mode: str = "print") -> None:
        if mode not in ("write", "print"):
            raise ValueError(f"mode {mode!r}: use 'write' or 'print'")
        if isinstance(timeout, bool) or not isinstance(timeout, int | float) \
                or not 0 < timeout < float("inf"):
            raise ConfigError(f"time limit {timeout!r}: use a positive number of seconds")
        engine = kb._engine
        if threading.get_ident() != engine.thread:
            raise RelrlError("the Prolog engine belongs to the thread that started it")
        self.timeout = float(timeout)
        self._engine = engine
        lib = engine.lib
        self._open = _bind(lib, "PL_open_query", c_void_p, c_void_p, c_int, c_void_p, c_size_t)
        self._next = _bind(lib, "PL_next_solution", c_int, c_void_p)
        self._close = _bind(lib, "PL_close_query", c_int, c_void_p)
        text = text.strip()
        if text.endswith("."):
            text = text[:-1]
        self._fid = engine.open_frame()
        self._args = engine.new_term_refs(5)
        engine.put(self._args, kb.module, {})
        engine.put(self._args + 1, text, {})
        engine.put_float(self._args + 2, self.timeout)
        engine.put(self._args + 3, mode, {})
        engine.put_variable(self._args + 4)
        pred = engine.predicate(b"gw_answer", 5, b"relrl_gateway")
        engine.calls += 1
        self._qid: int | None = self._open(None, _PL_Q_NODEBUG | _PL_Q_CATCH_EXCEPTION, pred,
                                           self._args)

    @property
    def closed(self) -> bool:
        """True once the query has no more answers or was closed."""
        return self._qid is None

    def next(self) -> Answer | None:
        """The next answer, or None when there is none (the query is then closed).

        Raises:
            QueryTimeout: this answer took longer than the time limit.
            PrologError, RuleError, UserError: the query raised (the query is then closed).
        """
        if self._qid is None:
            return None
        engine = self._engine
        mark = c_size_t()
        engine.mark_strings(byref(mark))
        try:
            engine.calls += 1
            engine.busy = True
            try:
                more = self._next(self._qid)
            finally:
                engine.busy = False
            if not more:
                ex = engine.exception(self._qid)
                detail = engine.get(ex) if ex else None
                self.close()
                if detail is None:
                    return None
                if detail == "$aborted":
                    raise Aborted(None, None)
                raise PrologError(f"query failed: {detail!r}", detail)
            result = engine.get(self._args + 4)
        finally:
            engine.release_strings(mark.value)
        if isinstance(result, tuple) and result[0] == "error":
            self.close()
            _raise_result(result, self.timeout)
        _, text, det = result  # type: ignore[misc]
        if det == "true":
            self.close()
        return Answer(str(text), det == "true")

    def again(self, mode: str) -> Answer | None:
        """The current answer written again: ``"write"`` (whole terms, as swipl's ``w``) or
        ``"print"`` (to depth 10, as ``p``); the mode stays for later answers."""
        if mode not in ("write", "print"):
            raise ValueError(f"mode {mode!r}: use 'write' or 'print'")
        if self._qid is None:
            return None
        engine = self._engine
        fid = engine.open_frame()
        try:
            t = engine.new_term_ref()
            engine.put(t, mode, {})
            pred = engine.predicate(b"gw_answer_again", 1, b"relrl_gateway")
            engine.call_predicate(None, _PL_Q_NODEBUG | _PL_Q_CATCH_EXCEPTION, pred, t)
        finally:
            engine.discard_frame(fid)
        return self.next()

    def close(self) -> None:
        """Discard the query and its remaining answers. Safe to call twice."""
        if self._qid is not None:
            qid, self._qid = self._qid, None
            self._close(qid)
            self._engine.discard_frame(self._fid)

    def __enter__(self) -> OpenQuery:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _bind(lib: Any, name: str, restype: Any, *argtypes: Any) -> Any:
    f = getattr(lib, name)
    f.restype = restype
    f.argtypes = list(argtypes)
    return f


