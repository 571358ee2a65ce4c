"""Logging for the command line: ``-v`` / ``-q`` and a log file for robot sessions.

``relrl -v CMD`` shows debug messages, ``relrl -q CMD`` only warnings and errors (and no
progress bars); by default info messages go to standard error. :func:`add_file` adds a
log file (``relrl run --out DIR`` writes ``DIR/run.log`` at debug level, whatever the
console shows), with times, so a session on a robot can be read afterwards.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path

__all__ = ["add_file", "quiet", "remove_file", "setup"]

FORMAT = "%(asctime)s %(levelname)-7s %(name)s: %(message)s"
_state = {"verbosity": 0}


def setup(verbosity: int = 0) -> None:
    """Configure the ``relrl`` loggers for the console.

    Args:
        verbosity: -1 quiet (warnings), 0 info, 1 or more debug.
    """
    _state["verbosity"] = verbosity
    root = logging.getLogger("relrl")
    level = logging.WARNING if verbosity < 0 else logging.INFO if verbosity == 0 \
        else logging.DEBUG
    for h in list(root.handlers):
        if getattr(h, "_relrl_console", False):
            root.removeHandler(h)
    handler = logging.StreamHandler(sys.stderr)
    handler._relrl_console = True  # type: ignore[attr-defined]
    handler.setLevel(level)
    handler.setFormatter(logging.Formatter("relrl: %(message)s" if verbosity <= 0
                                           else "%(levelname)s %(name)s: %(message)s"))
    root.addHandler(handler)
    root.setLevel(logging.DEBUG)


def quiet() -> bool:
    """Whether ``-q`` was given."""
    return _state["verbosity"] < 0


class _FileLog(logging.StreamHandler):
    """A log file written through relrl's one writer (:func:`relrl.outdir.open_stream`): a
    new file, never a link followed; when it cannot be written (a full disk) it falls
    silent -- the log must never be what stops a session."""

    def handleError(self, record: logging.LogRecord) -> None:  # noqa: N802 (logging's name)
        self.setLevel(logging.CRITICAL + 1)

    def close(self) -> None:
        try:
            self.stream.close()
        finally:
            super().close()


def add_file(path: str | Path) -> logging.Handler:
    """Also log everything (debug level, with times) to ``path``; returns the handler."""
    from relrl.outdir import open_stream

    handler = _FileLog(open_stream(path))
    handler.setLevel(logging.DEBUG)
    handler.setFormatter(logging.Formatter(FORMAT))
    root = logging.getLogger("relrl")
    root.addHandler(handler)
    if root.level == logging.NOTSET or root.level > logging.DEBUG:
        root.setLevel(logging.DEBUG)
    return handler


def remove_file(handler: logging.Handler) -> None:
    """Stop logging to a file added by :func:`add_file` and close it."""
    logging.getLogger("relrl").removeHandler(handler)
    handler.close()
