"""A user's query, one answer at a time, as at swipl's toplevel (``relrl shell``).

Prolog keeps the query open between its answers (``prolog/toplevel.pl``'s ``gw_answer/4``
through :class:`relrl.bridge.calls.Query`): each :meth:`OpenQuery.next` resumes it for one
more answer under the time limit, so output the goal writes comes out in order with the
answers and an endless generator costs nothing until asked. Answers are written by
Prolog's own writer: no term crosses the bridge.
"""

from __future__ import annotations

from dataclasses import dataclass

from relrl.bridge.calls import Prolog, Query, check_result
from relrl.errors import ConfigError
from relrl.terms import Term

__all__ = ["Answer", "OpenQuery"]

_MODES = ("write", "print", "values")


@dataclass(frozen=True)
class Answer:
    """One answer of an :class:`OpenQuery`.

    Attributes:
        text: the bindings as swipl's toplevel writes them (cycles factorized, deep terms
            written to depth 10 unless asked otherwise), ``""`` when there are none.
        last: no further answer can follow (the goal left no choice point).
        bindings: with mode ``"values"``, ``(name, value, printed)`` for each named
            variable (a value too deep or cyclic for Python is its printed text).
    """

    text: str
    last: bool
    bindings: tuple[tuple[str, Term, str], ...] = ()


class OpenQuery:
    """A user's query kept open between its answers (see
    :meth:`relrl.kb.KnowledgeBase.open_query`). Close it, or use it as a context manager.

    Args:
        transport: the process's Prolog, as the knowledge base holds it.
        module: the knowledge base's module.
        text: the query, with or without its final full stop.
        timeout: seconds each answer may take (positive: a user's query is always
            bounded); the clock stops between answers.
        mode: ``"print"`` writes terms to depth 10 (swipl's default), ``"write"`` whole;
            ``"values"`` gives the bindings as values instead of text.
    """

    def __init__(self, transport: Prolog, module: str, text: str, timeout: float,
                 mode: str = "print") -> None:
        if mode not in _MODES:
            raise ValueError(f"mode {mode!r}: use one of {', '.join(_MODES)}")
        if isinstance(timeout, bool) or not isinstance(timeout, int | float) \
                or not 0 < timeout < float("inf"):
            raise ConfigError(f"time limit {timeout!r}: use a positive number of seconds")
        self.timeout = float(timeout)
        text = text.strip()
        self._prolog = transport
        self._query: Query = transport.open(("relrl_gateway", "gw_answer"),
                                            [module, text.removesuffix("."), mode])

    @property
    def closed(self) -> bool:
        """True once the query has no more answers or was closed."""
        return self._query.closed

    def next(self) -> Answer | None:
        """The next answer, or None when there is none (the query is then closed).

        Raises:
            QueryTimeout: this answer took longer than the time limit.
            PrologError, RuleError, UserError: the query raised (the query is then closed).
        """
        result = self._query.next(self.timeout)
        if result is None:
            return None
        if result[0] == "error":
            self.close()
            check_result(result, self.timeout)
        _, text, det, bindings = result
        if det == "true":
            self.close()
        return Answer(str(text), det == "true",
                      tuple((name, value, printed) for (_, (_, name, value), printed)
                            in bindings))

    def again(self, mode: str) -> Answer | None:
        """The current answer written again: ``"write"`` (whole terms, as swipl's ``w``) or
        ``"print"`` (to depth 10, as ``p``); the mode stays for later answers."""
        if mode not in ("write", "print"):
            raise ValueError(f"mode {mode!r}: use 'write' or 'print'")
        if self.closed:
            return None
        self._prolog.api("answer_again", mode, timeout=self.timeout)
        return self.next()

    def close(self) -> None:
        """Discard the query and its remaining answers. Safe to call twice."""
        self._query.close()

    def __enter__(self) -> OpenQuery:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
