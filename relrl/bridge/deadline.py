"""A call's time limit and Ctrl-C, as SWI-Prolog users know them.

Every call into Prolog runs under a time limit, as if by ``call_with_time_limit/2``: armed
when the call starts (:meth:`Watchdog.arm`) and disarmed when it returns, whatever way it
ends (:meth:`Watchdog.disarm`, in a ``finally``). An open query's limit is armed only while
an answer is sought. Between calls nothing is armed, so no limit outlives its call.

One thread, the watchdog, sleeps until the running call's deadline. If the call still runs
then, it raises :data:`SIG_TIME` in Prolog's thread (``PL_thread_raise``: a Prolog signal,
handled at the goal's next call port or in a blocking system call), whose handler in
``prolog/guard.pl`` throws ``time_limit_exceeded`` inside the goal — what
``call_with_time_limit/2``'s alarm throws. Within :meth:`Watchdog.interruptible`, Ctrl-C
(which Python sees only between bytecodes, not while Prolog runs; SIGTERM and SIGHUP too,
when Python handles them) reaches the watchdog
through :func:`signal.set_wakeup_fd` and raises :data:`SIG_INTERRUPT`, whose handler throws
``relrl_interrupted``: the goal stops at once, as at swipl's toplevel.

The signal is raised again every :data:`RAISE_AGAIN` seconds until the call returns. One
raised as the call was returning is still pending when it has returned:
:meth:`Watchdog.disarm` says so, and the caller lets Prolog take it outside any call.

Arming costs a lock and two assignments: the thread is not woken for each call (a control
step is some 50 µs; ``alarm/4`` per call, which wakes SWI-Prolog's scheduler thread, cost
25 µs more). It wakes when a deadline may have passed — about once per time limit — or
when a call has a shorter limit than any before.
"""

from __future__ import annotations

import math
import os
import select
import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = ["Watchdog", "SIG_TIME", "SIG_INTERRUPT", "SIG_TICK"]

#: The Prolog signals the watchdog raises (numbers of Prolog's signal table; the OS does
#: not deliver them: see :mod:`relrl.bridge.lib`).
SIG_TIME = int(signal.SIGVTALRM)
SIG_INTERRUPT = int(signal.SIGUSR1)
#: The signal of a watched call (:meth:`Watchdog.arm` with ``tick``): raised every
#: :data:`RAISE_AGAIN` seconds, Prolog's handler decides (prolog/guard.pl, progress_watch/2).
SIG_TICK = int(signal.SIGPROF)
#: Seconds between raises while a call runs past its deadline: a signal taken before the
#: guard of the call was entered does nothing, the next one stops the goal.
RAISE_AGAIN = 0.1
#: The signals that stop the running call within :meth:`Watchdog.interruptible` (when the
#: process has a Python handler for them: Ctrl-C always; SIGTERM and SIGHUP while a command
#: keeps what it learned on a stop).
STOP_SIGNALS = tuple(int(getattr(signal, n)) for n in ("SIGINT", "SIGTERM", "SIGHUP")
                     if hasattr(signal, n))


class Watchdog:
    """Time limits and Ctrl-C for the calls of one Prolog thread.

    Args:
        raise_signal: raises a Prolog signal in Prolog's thread (safe from any thread).
    """

    def __init__(self, raise_signal: Callable[[int], object]) -> None:
        self._raise = raise_signal
        self._lock = threading.Lock()
        self._deadline: float | None = None     # the running call's; None between calls
        self._raised = False                    # a signal was raised for the running call
        self._signal = SIG_TIME                 # what the running call's deadline raises
        self._stop = False                      # a stop signal came while the call ran
        self._shortest = 10.0                   # the shortest limit so far: the idle sleep
        self._wake_at = math.inf                # when the thread wakes next
        self._interruptible = False
        self._wake_r, self._wake_w = os.pipe()
        for fd in (self._wake_r, self._wake_w):
            os.set_blocking(fd, False)
        threading.Thread(target=self._watch, name="relrl-watchdog", daemon=True).start()

    def arm(self, limit: float | None, *, tick: bool = False) -> None:
        """A call with a time limit of ``limit`` seconds (0 or None: none) starts; with
        ``tick``, a watched call: :data:`SIG_TICK` every :data:`RAISE_AGAIN` seconds instead,
        Prolog's handler holding the limit (it counts from the call's last progress)."""
        now = time.monotonic()
        if tick:
            limit = RAISE_AGAIN
        deadline = now + limit if limit and limit > 0 else math.inf
        with self._lock:
            self._deadline = deadline
            self._signal = SIG_TICK if tick else SIG_TIME
            self._raised = self._stop = False
        if deadline < self._wake_at:            # sooner than the thread looks next
            self._shortest = min(self._shortest, limit)
            self._nudge()

    def disarm(self) -> bool:
        """The call has returned. True when a signal was raised for it (it may be pending:
        the caller lets Prolog take it outside any call)."""
        with self._lock:
            self._deadline = None
            raised, self._raised, self._stop = self._raised, False, False
        return raised

    @contextmanager
    def interruptible(self) -> Iterator[None]:
        """Within the block, Ctrl-C (SIGINT) stops the running call at once (a user's
        query at a terminal); Python's ``KeyboardInterrupt`` follows when it returns. So
        do SIGTERM and SIGHUP when Python handles them (a command that keeps what it
        learned when stopped). Outside the main thread this does nothing."""
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        old = signal.set_wakeup_fd(self._wake_w, warn_on_full_buffer=False)
        self._interruptible = True
        try:
            yield
        finally:
            self._interruptible = False
            signal.set_wakeup_fd(old)

    def _nudge(self) -> None:
        try:
            os.write(self._wake_w, b"\0")
        except BlockingIOError:                 # the pipe is full: the thread is awake
            pass

    def _watch(self) -> None:
        while True:
            with self._lock:
                now = time.monotonic()
                deadline = self._deadline
                if deadline is not None and self._stop:
                    self._raised = True               # Ctrl-C (also after the time limit's
                    self._raise(SIG_INTERRUPT)        # signals): again until the call ends
                    deadline = now + RAISE_AGAIN
                elif deadline is not None and now >= deadline:
                    self._raised = True
                    self._raise(self._signal)
                    deadline = now + RAISE_AGAIN      # until the call ends
                elif deadline is None or deadline == math.inf:
                    deadline = now + self._shortest    # a call armed meanwhile ends later
                self._wake_at = deadline
            ready, _, _ = select.select([self._wake_r], [], [], max(deadline - now, 0.0))
            if ready:
                data = os.read(self._wake_r, 512)
                if self._interruptible and any(s in data for s in STOP_SIGNALS):
                    with self._lock:
                        if self._deadline is not None:
                            self._stop = True         # raised at the top of the loop
