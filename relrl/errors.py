"""Errors raised by relrl.

Every error a user can cause (a bad Prolog file, a bad episode script, a bad flag, a missing
device) is a :class:`UserError`. The command line prints such an error as one line and exits
with status 2; anything else is a bug and keeps its traceback.

The lower layers stand alone: ``head`` and ``perception`` import nothing from relrl and have
their own error bases (:class:`head.errors.HeadError`, :class:`perception.errors.PerceptionError`).
:data:`USER_ERRORS` gathers the three bases, so one ``except USER_ERRORS`` (the command line's)
catches every error a user can cause. It is looked up lazily: importing this module does not
import ``head`` or ``perception``.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "USER_ERRORS",  # noqa: F822 (module __getattr__: imports head and perception lazily)
    "RelrlError",
    "UserError",
    "PrologMissing",
    "JobFailed",
    "JobCrashed",
    "EngineError",
    "PrologError",
    "AnswerTooLarge",
    "PrologLoadError",
    "QueryTimeout",
    "RuleError",
    "PolicyError",
    "DomainError",
    "ConfigError",
    "OutputError",
]


class RelrlError(Exception):
    """Base class of every error relrl raises on purpose."""


class UserError(RelrlError):
    """An error the user can fix: printed as one line, exit status 2."""


class JobFailed(UserError):
    """An experiment job's relrl error (or a lost worker), raised inside the engine that runs
    the jobs to stop the run (:mod:`relrl.experiments.runner`)."""


class JobCrashed(RuntimeError):
    """An experiment job raised something that is not a relrl error: a bug; carries the
    traceback."""


class EngineError(RelrlError):
    """A goal of relrl's engine failed where it must succeed (a bug, not a user error)."""


class PrologError(RelrlError):
    """A Prolog exception raised while running a goal.

    Attributes:
        term: the Prolog error term as plain Python values (see :mod:`relrl.terms`).
        message: Prolog's own rendering of the error, one line.
    """

    def __init__(self, message: str, term: Any = None) -> None:
        super().__init__(message)
        self.message = message
        self.term = term


class AnswerTooLarge(PrologError, UserError):
    """An answer of Prolog that cannot be passed to Python: a term nested deeper, or a list
    longer, than relrl reads (what a user's rules built: one line, not a traceback)."""


class PrologLoadError(UserError):
    """A Prolog file could not be loaded cleanly.

    Attributes:
        path: the file that failed.
        line: the first line with a problem (``None`` when unknown).
        problems: every ``(path, line, text)`` reported while loading.
    """

    def __init__(self, path: str, line: int | None, text: str,
                 problems: list[tuple[str, int | None, str]] | None = None) -> None:
        where = f"{path}:{line}" if line else str(path)
        super().__init__(f"{where}: {text}")
        self.path = path
        self.line = line
        self.text = text
        self.problems = problems or [(path, line, text)]


class QueryTimeout(UserError):
    """A Prolog goal ran longer than its time bound (a runaway rule).

    Attributes:
        rule: the domain goal that was running (text), when it came from one.
        where: ``file:line`` of that goal's predicate, when known.
    """

    def __init__(self, message: str, rule: str | None = None, where: str | None = None) -> None:
        super().__init__(message)
        self.rule = rule
        self.where = where


class RuleError(UserError):
    """A goal of the user's domain raised an error (a stack overflow, an undefined
    predicate, a call of halt/abort ...) while the engine ran it; the message names the rule
    and its file and line.

    Attributes:
        rule: the goal, as text; ``where``: ``file:line``; ``term``: the Prolog error.
    """

    def __init__(self, message: str, rule: str | None = None, where: str | None = None,
                 term: Any = None) -> None:
        super().__init__(message)
        self.rule = rule
        self.where = where
        self.term = term


class PolicyError(UserError):
    """A policy file is not this learner's policy for this domain (or not a policy at all);
    the message names the file and line. Policies are read as data, never run."""


class DomainError(UserError):
    """A domain file loaded but does not validate (see ``relrl check``)."""


class PrologMissing(UserError):
    """SWI-Prolog is not installed, or its library does not start (``make setup`` installs
    it)."""


class ConfigError(UserError):
    """A bad option value: a flag, a parameter, a configuration file entry."""


class OutputError(ConfigError):
    """An output folder or file that cannot be used: a file where a folder is needed, a folder
    that cannot be created or written, a non-empty folder of another run."""


#: built on first use by :func:`__getattr__` (the lower layers are imported only then).
_user_errors: tuple[type[Exception], ...] | None = None


def __getattr__(name: str) -> Any:
    """``USER_ERRORS``: UserError, HeadError and PerceptionError, for one ``except``."""
    global _user_errors
    if name == "USER_ERRORS":
        if _user_errors is None:
            from head.errors import HeadError
            from perception.errors import PerceptionError

            _user_errors = (UserError, HeadError, PerceptionError)
        return _user_errors
    raise AttributeError(f"module 'relrl.errors' has no attribute {name!r}")
