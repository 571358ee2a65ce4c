"""The one gateway to Prolog: :class:`KnowledgeBase`.

A knowledge base is a Prolog module of its own holding a domain and its working memory: two
knowledge bases in one process never see each other's clauses. Underneath is the transport
(:mod:`relrl.bridge`): SWI-Prolog started once, lazily, with relrl's knowledge layer
(``prolog/``); values passed as terms, never pasted into a goal's text; every call run once
under a time limit and its errors raised as relrl exceptions naming the file and line.

SWI-Prolog gives one engine per process and it is not safe across threads: a call from a
thread other than the one that started it raises. Parallel experiments use processes.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from contextlib import AbstractContextManager
from dataclasses import dataclass
from pathlib import Path

from relrl.bridge.calls import Aborted, display_path, prolog, strip_kb_module
from relrl.bridge.marshal import Cached
from relrl.errors import EngineError, PrologLoadError
from relrl.query import OpenQuery
from relrl.resources import prolog_dir
from relrl.terms import Term, Var

__all__ = ["KnowledgeBase", "Problem", "Cached", "PROLOG_DIR", "gateway_calls", "layer_api",
           "DEFAULT_TIMEOUT"]

#: Where the knowledge layer's .pl files live: package data (override with RELRL_PROLOG_DIR).
PROLOG_DIR = prolog_dir()
#: Seconds a single gateway call may run before it raises QueryTimeout.
DEFAULT_TIMEOUT = 10.0


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


def gateway_calls() -> int:
    """Number of calls into Prolog made through the gateway so far in this process."""
    return prolog().calls


def layer_api(goal: str, *arguments: Term, timeout: float) -> list | None:
    """Call the goal of the knowledge layer that ``python_api/2`` names ``goal`` once, for
    what concerns no knowledge base (the learners' catalogue is asked before any knowledge
    base exists): the one door to Prolog besides :class:`KnowledgeBase`. Returns the values
    of its :class:`Var` arguments, or None when it fails."""
    return prolog().api(goal, *arguments, timeout=timeout)


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
        self._prolog = prolog()
        self.timeout = timeout
        self.files: list[Path] = []
        self.warnings: list[Problem] = []
        out = self._prolog.api("new_kb", Var(), timeout=timeout)
        self.module: str = out[0]  # type: ignore[index]
        self._closed = False
        for path in domains:
            self.load(path, strict=strict)

    # -- loading ---------------------------------------------------------------------------

    def load(self, path: str | os.PathLike, *, strict: bool = True) -> list[Problem]:
        """Consult a domain file into this knowledge base, under the time limit (Ctrl-C
        stops it at once).

        Returns the warnings when ``strict`` is False.

        Raises:
            PrologLoadError: the file is missing, has a syntax error or another load error,
                or (when ``strict``) a warning; the message names file and line.
        """
        p = Path(path)
        from relrl.textfile import not_utf8

        if (problem := not_utf8(p)) is not None:
            raise PrologLoadError(display_path(str(p)), *problem)
        try:
            with self.interruptible():          # Ctrl-C stops a directive that never ends
                out = self._prolog.api("load", str(p), self.module, Var(),
                                       timeout=self.timeout)
        except Aborted as exc:
            raise PrologLoadError(display_path(str(p)), None,
                                  "abort/0 called while loading") from exc
        problems = [Problem(kind, display_path(str(f) if f else str(p)), line or None,
                            strip_kb_module(msg))
                    for (_, kind, f, line, msg) in out[0]]  # type: ignore[index]
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
        goal: Term = (":", module or self.module, (name, *arguments) if arguments else name)
        outputs = [i for i, a in enumerate(arguments) if isinstance(a, Var)]
        return self._prolog.run(goal, self.timeout if timeout is None else timeout, outputs)

    def holds(self, goal: Term, *, timeout: float | None = None) -> bool:
        """True when ``goal`` (a term) succeeds in this knowledge base."""
        out = self._prolog.run((":", self.module, goal),
                               self.timeout if timeout is None else timeout)
        return out is not None

    def api(self, goal: str, *arguments: Term, timeout: float | None = None) -> list | None:
        """Call the goal of the knowledge layer that ``python_api/2`` (prolog/gateway.pl)
        names ``goal`` once, under this knowledge base's time limit unless ``timeout`` is
        given: the values of its :class:`Var` arguments, in order, or None when it fails.
        :class:`relrl.engine.Engine` and the methods below call the layer through it."""
        return self._prolog.api(goal, *arguments,
                                timeout=self.timeout if timeout is None else timeout)

    def api_det(self, goal: str, *arguments: Term, timeout: float | None = None) -> list:
        """:meth:`api` for a goal that must succeed.

        Raises:
            EngineError: the goal failed (a bug of the layer, not a user's error).
        """
        out = self.api(goal, *arguments, timeout=timeout)
        if out is None:
            module, name = self.api_goal(goal)
            raise EngineError(f"{module}:{name}/{len(arguments)} failed in {self.module}")
        return out

    def api_watched(self, goal: str, *arguments: Term, seconds: float) -> list | None:
        """Call the layer's ``goal`` with ``arguments`` and one more output argument under
        the guard's progress watch (a world's calls, prolog/guard.pl progress_watch/2): a
        rule is stopped once it has run ``seconds`` since the world's last step, however
        long the whole call. The output's value in a one-element list, or None when the goal
        fails.

        Raises:
            QueryTimeout: a rule ran ``seconds`` with no step.
        """
        module, predicate = self._prolog.goal(goal)
        watched, watcher = self._prolog.goal("watched")
        inner = (":", module, (predicate, *arguments, Var()))
        values = self._prolog.run((":", watched, (watcher, seconds, inner)), seconds, [1],
                                  watched=True)
        return None if values is None else [values[0][2][-1]]

    def api_goal(self, goal: str) -> tuple[str, str]:
        """``(module, predicate)`` of the goal ``python_api/2`` names ``goal``.

        Raises:
            RelrlError: the layer declares no goal of that name.
        """
        return self._prolog.goal(goal)

    def step(self, percepts: Cached, emitted: int, mode: str, want: list[str]) -> tuple | None:
        """The control step of this knowledge base's engine in one gateway call (see
        :class:`relrl.engine.Engine`, which decodes it); None when the step failed."""
        return self._prolog.step(self.module, percepts, emitted, mode, want,
                                 float(self.timeout or 0))

    def hold(self, names: Iterable[str]) -> None:
        """Keep the atoms ``names`` (necessities, ...) so that the step reads them by
        handle."""
        for name in names:
            self._prolog.marshal.hold(name)

    def query(self, text: str, *, max_solutions: int = 100,
              timeout: float | None = None) -> tuple[list[list[tuple[str, Term, str]]], bool]:
        """Run a query typed by a user (Prolog syntax) for its first answers.

        Returns ``(solutions, more)``: each solution is a list of ``(variable name, value,
        value printed as Prolog)``; ``more`` is True when there were more than
        ``max_solutions``.

        Raises:
            PrologError: syntax error or exception in the query.
            QueryTimeout: one answer took longer than the time limit.
        """
        solutions = []
        with self.open_query(text, timeout=timeout, mode="values") as q:
            while (answer := q.next()) is not None:
                if len(solutions) == max_solutions:
                    return solutions, True
                solutions.append(list(answer.bindings))
        return solutions, False

    def open_query(self, text: str, *, timeout: float | None = None,
                   mode: str = "print") -> OpenQuery:
        """Open a query typed by a user (Prolog syntax) to take its answers one at a time,
        as swipl's toplevel does (``relrl shell``; see :class:`relrl.query.OpenQuery`).
        ``timeout``: seconds each answer may take (default: this knowledge base's)."""
        return OpenQuery(self._prolog, self.module, text,
                         self.timeout if timeout is None else timeout, mode)

    def interruptible(self) -> AbstractContextManager[None]:
        """A context in which Ctrl-C stops the running goal at once (a user's queries at a
        terminal; see :meth:`relrl.bridge.deadline.Watchdog.interruptible`)."""
        return self._prolog.watchdog.interruptible()

    # -- the knowledge layer ---------------------------------------------------------------

    # Each method below is one goal of the knowledge layer, called by its name in
    # prolog/gateway.pl's python_api/2.

    def insert(self, elements: Iterable[Term]) -> None:
        """One insertion of ``elements`` into working memory (they get age 0)."""
        self.api_det("wm_insert", self.module, list(elements))

    def memory(self) -> list[tuple[int, Term]]:
        """Working memory as ``(age, element)`` pairs, youngest first."""
        pairs = self.api_det("wm_elements", self.module, Var())[0]
        return [(age, element) for (_, age, element) in pairs]

    def clear_memory(self) -> None:
        """Forget every element of working memory."""
        self.api_det("wm_clear", self.module)

    def state_code(self) -> int:
        """The current state code: sum of 2^x over the stimuli and facts that hold now."""
        return self.api_det("state_code", self.module, Var())[0]

    def state_terms(self) -> list[Term]:
        """The stimuli and facts that hold now, as ``("stimulus", S)`` / ``("fact", F)``."""
        return self.api_det("state_terms", self.module, Var())[0]

    def decode_state(self, code: int) -> list[Term]:
        """The stimuli and facts whose bits are set in ``code``."""
        return self.api_det("state_decode", self.module, code, Var())[0]

    def features(self) -> list[Term]:
        """Every stimulus and fact in code order (position x has code 2^x)."""
        return self.api_det("state_features", self.module, Var())[0]

    def allowed_responses(self) -> list[Term]:
        """The responses the constraint rules allow now, in declaration order."""
        return self.api_det("allowed_responses", self.module, Var())[0]

    def declarations(self, kind: str) -> list[Term]:
        """All ``kind`` declarations (``stimulus``, ``fact``, ``response``, ``necessity``)."""
        return [t[1] for t in self.find(kind, Var("X"))]

    def find(self, name: str, *arguments: Term) -> list[Term]:
        """Every declaration ``name(arguments...)`` of the domain, as terms (a template with
        :class:`~relrl.terms.Var` arguments; nothing but the domain's own clauses is run)."""
        return self.api_det("findall", self.module, (name, *arguments), Var())[0]

    # -- life cycle ------------------------------------------------------------------------

    def close(self) -> None:
        """Forget this knowledge base's clauses and memory. Safe to call twice."""
        if not self._closed:
            self._closed = True
            self._prolog.api("drop_kb", self.module, timeout=self.timeout)

    def __enter__(self) -> KnowledgeBase:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        files = ", ".join(str(f) for f in self.files)
        return f"KnowledgeBase({self.module}: {files})"
