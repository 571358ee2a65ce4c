"""Progress of long commands: tqdm bars on a terminal, log lines everywhere else.

:func:`progress` gives a bar with rate and ETA (tqdm) when standard error is a terminal;
when it is not (a log file, CI, a pipe, a worker process) the same object writes a line
through :mod:`logging` at most every ``interval`` seconds -- ``relrl.progress: 40/100 units
[00:05<00:07, 8.00 unit/s]`` -- so a log shows how far a run got and how long it has left.
Worker processes report to their parent (see :mod:`relrl.experiments.runner`), which owns
the bar.
"""

from __future__ import annotations

import logging
import sys
import time
from typing import Any

__all__ = ["Progress", "progress"]

log = logging.getLogger("relrl.progress")

#: seconds between log lines when there is no terminal.
LOG_INTERVAL = 10.0


class Progress:
    """Counts work done; draws a tqdm bar or logs lines (see :func:`progress`)."""

    def __init__(self, total: int | None, desc: str, unit: str, *, bar: bool,
                 interval: float = LOG_INTERVAL, enabled: bool = True) -> None:
        self.total, self.desc, self.unit = total, desc, unit
        self.n = 0
        self.enabled = enabled
        self.interval = interval
        self._t0 = time.monotonic()
        self._last = self._t0
        self._bar: Any = None
        if enabled and bar:
            from tqdm import tqdm

            # a terminal that reports no size (a bare pseudo-terminal, as a test harness or
            # a supervisor opens) makes tqdm draw nothing at all: give it 80 x 20
            sized = _terminal_size() > (0, 0)
            self._bar = tqdm(total=total, desc=desc, unit=unit, file=sys.stderr,
                             dynamic_ncols=sized, ncols=None if sized else 80,
                             nrows=None if sized else 20, leave=False)

    def update(self, n: int = 1) -> None:
        """``n`` more done."""
        self.n += n
        if self._bar is not None:
            self._bar.update(n)
        elif self.enabled:
            now = time.monotonic()
            if now - self._last >= self.interval:
                self._last = now
                log.info("%s", self.line())

    def grow(self, n: int) -> None:
        """``n`` more pieces of work than the total said (a total not known: nothing)."""
        if self.total is None:
            return
        self.total += n
        if self._bar is not None:
            self._bar.total = self.total
            self._bar.refresh()

    def set_description(self, text: str) -> None:
        """Change what the bar says."""
        self.desc = text
        if self._bar is not None:
            self._bar.set_description(text)

    def line(self) -> str:
        """``desc: n/total unit [elapsed<remaining, rate]`` (tqdm's format)."""
        from tqdm import tqdm

        return tqdm.format_meter(self.n, self.total, time.monotonic() - self._t0,
                                 prefix=self.desc, unit=f" {self.unit}", ncols=0)

    def close(self) -> None:
        """Finish (safe twice): the bar goes; a log gets the last line."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self.enabled and self.n:
            log.debug("%s", self.line())
        self.enabled = False

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _terminal_size() -> tuple[int, int]:
    """Columns and lines of the terminal on standard error (0s when it reports none)."""
    import os

    try:
        size = os.get_terminal_size(sys.stderr.fileno())
    except (OSError, ValueError, AttributeError):
        return (0, 0)
    return (size.columns, size.lines) if size.columns > 0 and size.lines > 0 else (0, 0)


def progress(total: int | None, desc: str, *, unit: str = "it", enabled: bool = True,
             interval: float = LOG_INTERVAL) -> Progress:
    """A progress counter for ``total`` pieces of work.

    Args:
        total: how many (``None``: unknown, no ETA).
        desc: what is being done.
        unit: what one piece is called.
        enabled: ``False`` shows nothing (``--live`` prints its own lines; ``-q``).
        interval: seconds between log lines when there is no terminal.
    """
    from relrl.log import quiet

    enabled = enabled and not quiet()
    return Progress(total, desc, unit, bar=sys.stderr.isatty(), interval=interval,
                    enabled=enabled)
