"""Running an experiment's independent jobs: local worker processes or a Ray cluster.

A *job* is a top-level function called as ``fn(*args, report=report)``; it returns a
JSON-ready dict and may call ``report(event)`` with small dicts as it goes (``{"kind":
"point", ...}`` for a finished evaluation point, which also advances the progress bar). Each
job runs in a process of its own Prolog engine (SWI-Prolog embedded: one per process).

Engines are looked up by name (:data:`ENGINES`): ``local`` (the default; spawned worker
processes on this machine) and ``ray`` (:mod:`relrl.experiments.ray_engine`; the same jobs on
a Ray cluster). Both return the same results for the same jobs.

Stopping. :func:`run_jobs` turns SIGINT (Ctrl-C), SIGTERM and SIGHUP (the terminal closed)
into a clean stop: the workers are ended (SIGTERM, then SIGKILL after half a second), the jobs
finished so far and the events of the unfinished ones are returned in a :class:`Outcome`
marked ``interrupted``, and the caller writes them (marked partial). Inside
:func:`command_signals` (the experiment commands) a signal after the jobs waits until the
outputs and the record are written. Workers ignore SIGINT and SIGHUP (a terminal's Ctrl-C or
hang-up reaches the whole process group; the parent alone decides) and die with the parent
(Linux ``PR_SET_PDEATHSIG``), so no worker outlives the run. Progress (:mod:`relrl.progress`: a bar
with ETA on a terminal, log lines elsewhere) counts the jobs' ``point`` events.

Failures. A job that raises a relrl error (a bad domain file, a runaway rule) stops the run;
so does a worker that dies (a domain calling ``halt/0``, a crash in Prolog: :class:`WorkerLost`).
The jobs finished so far are kept: the :class:`Outcome` carries the error's one line in
``error`` and the caller writes what finished (marked partial) before reporting it. Anything
else is a bug and keeps its traceback (:class:`JobCrashed`).
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from relrl.errors import ConfigError, JobCrashed, JobFailed, UserError
from relrl.experiments.ray_engine import run_ray

__all__ = ["ENGINES", "STOP_SIGNALS", "CommandSignals", "Outcome", "ProgressBar",
           "Stopped", "WorkerLost", "command_signals", "raise_kept", "run_jobs"]

#: a job function: ``fn(*args, report=callable) -> dict``.
JobFn = Callable[..., dict[str, Any]]


class WorkerLost(UserError):
    """A worker process ended without finishing its job (``halt/0`` in a domain, a crash)."""


@dataclass
class Outcome:
    """What :func:`run_jobs` brings back.

    Attributes:
        results: per job (in input order) its result, or ``None`` if it did not finish.
        events: per job the events it reported, in order (finished jobs included).
        interrupted: the run was stopped by a signal (the name, e.g. ``SIGINT``), or None.
        error: the one line of the relrl error that stopped the run, or None.
        seconds: wall-clock time of the run.
    """

    results: list[dict[str, Any] | None]
    events: list[list[dict[str, Any]]]
    interrupted: str | None = None
    error: str | None = None
    seconds: float = 0.0
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def complete(self) -> bool:
        """Every job finished."""
        return all(r is not None for r in self.results)


class ProgressBar:
    """The experiment's progress (:func:`relrl.progress.progress`): a tqdm bar with ETA on
    a terminal, log lines otherwise; workers report to the parent, which owns it."""

    def __init__(self, total: int) -> None:
        from relrl.progress import progress

        self.total = total
        self._progress = progress(total, "experiment", unit="point")

    @property
    def done(self) -> int:
        """Units done so far."""
        return self._progress.n

    def update(self, label: str, units: int = 1) -> None:
        """``units`` more done (``label`` says which)."""
        self._progress.set_description(label)
        self._progress.update(units)

    def grow(self, units: int) -> None:
        """``units`` more to do than the bar was made for (a job learning again)."""
        self.total += units
        self._progress.grow(units)

    def close(self) -> None:
        """End the bar."""
        self._progress.close()


def raise_kept(error: str, out: Any) -> None:
    """Raise the one line of a job's failure, saying where the finished jobs were kept."""
    raise UserError(f"{error} (the run stopped; what finished is in {out}/results.json, "
                    "marked partial)")


class _Stop(Exception):
    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.name = signal.Signals(signum).name


class Stopped(KeyboardInterrupt):
    """A stop signal before the jobs started: the command ends at once (status 128 + N).

    Attributes:
        signum: the signal.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


#: the signals that stop an experiment (SIGHUP: its terminal was closed).
STOP_SIGNALS = tuple(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP")
                     if hasattr(signal, n))


class CommandSignals:
    """What SIGINT, SIGTERM and SIGHUP do over one experiment command.

    Before the jobs a signal ends the command at once (:class:`Stopped`); while they run
    (:func:`stop_on_signals`) it stops them, keeping what finished; once they are over it
    waits: the outputs and the folder's record are written whole, then the command ends
    with 128 + N.

    Attributes:
        signum: the first signal received, or ``None``.
        stopped: set by a signal while the jobs run.
    """

    def __init__(self) -> None:
        self.signum: int | None = None
        self.phase = "start"
        self.stopped = threading.Event()

    def __call__(self, signum: int, frame: Any) -> None:
        self.signum = self.signum or signum
        if self.phase == "start":
            raise Stopped(signum)
        if self.phase == "jobs":
            first = not self.stopped.is_set()
            if first:
                self.stopped.signal_name = signal.Signals(signum).name  # type: ignore
                self.stopped.set()
                raise _Stop(signum)
        # after the jobs: wait for the outputs (the command reads signum at its end)


_ACTIVE: list[CommandSignals] = []


@contextmanager
def command_signals() -> Iterator[CommandSignals]:
    """Install :class:`CommandSignals` for the block (main thread only; elsewhere the block
    runs with the handlers it has); the old handlers come back afterwards."""
    handler = CommandSignals()
    if threading.current_thread() is not threading.main_thread():
        yield handler
        return
    old = {s: signal.signal(s, handler) for s in STOP_SIGNALS}
    _ACTIVE.append(handler)
    try:
        yield handler
    finally:
        _ACTIVE.remove(handler)
        for s, h in old.items():
            signal.signal(s, h)


@contextmanager
def stop_on_signals() -> Iterator[threading.Event]:
    """Within the block, SIGINT, SIGTERM and SIGHUP set the yielded event (and interrupt a
    blocking wait once) instead of ending the process. Inside :func:`command_signals` the
    command's handler does it (and holds later signals until the outputs are written);
    otherwise handlers are installed for the block only.

    Only the main thread can install handlers; elsewhere the block runs unchanged.
    """
    with contextlib.ExitStack() as stack:
        handler = _ACTIVE[-1] if _ACTIVE else stack.enter_context(command_signals())
        handler.phase = "jobs"
        try:
            yield handler.stopped
        finally:
            handler.phase = "after"


def run_jobs(fn: JobFn, arglist: list[tuple], *, workers: int = 1, engine: str = "local",
             address: str | None = None, units: int = 1,
             label: Callable[[tuple], str] = lambda args: str(args[:3]),
             on_event: Callable[[int, dict[str, Any]], None] | None = None) -> Outcome:
    """Run ``fn(*args, report=...)`` for every ``args`` in ``arglist``.

    Args:
        fn: the job function (top level, so that worker processes can import it).
        arglist: the jobs' positional arguments (picklable).
        workers: processes (local) or CPUs asked of a local Ray instance.
        engine: a name in :data:`ENGINES`.
        address: the Ray cluster to join (engine ``ray``); ``None`` starts a local one.
        units: progress units per job (the ``point`` events it reports).
        label: a short label of a job for the progress bar and error messages.
        on_event: called in this process with ``(job index, event)`` as events arrive.

    Returns:
        An :class:`Outcome`: ``interrupted`` set when a signal stopped the run, ``error`` when
        a job failed with a relrl error or a worker was lost (the other jobs are stopped; the
        finished ones are kept).

    Raises:
        UserError: a bad engine, worker count or address (before any job runs).
        JobCrashed: a job failed with another exception (a bug; the worker's traceback).
    """
    try:
        start = ENGINES[engine]
    except KeyError:
        raise ConfigError(f"unknown engine {engine!r} (engines: {', '.join(ENGINES)})") \
            from None
    if workers < 1:
        raise ConfigError(f"workers must be at least 1, not {workers}")
    bar = ProgressBar(units * len(arglist))
    outcome = Outcome([None] * len(arglist), [[] for _ in arglist])

    def event(index: int, ev: dict[str, Any]) -> None:
        outcome.events[index].append(ev)
        if ev.get("kind") == "point":
            bar.update(f"{label(arglist[index])} point {ev.get('point', '')}")
        elif ev.get("kind") == "check" and ev["entry"].get("restart"):
            bar.grow(units - 1)     # a restart's points: a job's less its first evaluation
        if on_event is not None:
            on_event(index, ev)

    t0 = time.perf_counter()
    try:
        with stop_on_signals() as stopped:
            try:
                start(fn, arglist, outcome, event, workers=workers, address=address,
                      label=label, stopped=stopped)
            except _Stop as stop:
                outcome.interrupted = stop.name
            except JobFailed as failed:
                outcome.error = str(failed)
            if stopped.is_set() and outcome.interrupted is None:
                outcome.interrupted = getattr(stopped, "signal_name", "SIGINT")
    finally:
        bar.close()
        outcome.seconds = time.perf_counter() - t0
    return outcome


# ---- the local engine ----------------------------------------------------------------------

def _die_with_parent() -> None:
    """Ask Linux to SIGKILL this process when its parent dies (no orphans)."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def _worker_main(conn: Any) -> None:
    """A worker process: run the jobs the parent sends until it sends None (or goes away)."""
    import traceback

    from relrl.errors import RelrlError

    # a terminal's Ctrl-C or hang-up reaches the whole group: the parent alone decides (its
    # SIGTERM ends the worker)
    for sig in STOP_SIGNALS:
        if sig != signal.SIGTERM:
            signal.signal(sig, signal.SIG_IGN)
    _die_with_parent()
    while True:
        try:
            task = conn.recv()
        except (EOFError, OSError):
            return
        if task is None:
            return
        index, fn, args = task

        def report(ev: dict[str, Any], index: int = index) -> None:
            conn.send(("event", index, ev))

        try:
            result = fn(*args, report=report)
        except RelrlError as exc:
            conn.send(("error", index, type(exc).__name__, str(exc)))
            continue
        except Exception as exc:  # noqa: BLE001 - a bug: ship its traceback to the parent
            conn.send(("crash", index, type(exc).__name__,
                       "".join(traceback.format_exception(exc))))
            continue
        conn.send(("done", index, result))


def _stop_processes(procs: list[Any], grace: float = 0.5) -> None:
    """End worker processes: SIGTERM, then SIGKILL for those alive after ``grace`` s."""
    for p in procs:
        if p.is_alive():
            try:
                os.kill(p.pid, signal.SIGTERM)
            except (ProcessLookupError, TypeError):
                pass
    deadline = time.monotonic() + grace
    for p in procs:
        p.join(max(0.0, deadline - time.monotonic()))
    for p in procs:
        if p.is_alive():
            p.kill()
    for p in procs:
        p.join(1.0)


def _run_local(fn: JobFn, arglist: list[tuple], outcome: Outcome,
               event: Callable[[int, dict[str, Any]], None], *, workers: int,
               address: str | None, label: Callable[[tuple], str],
               stopped: threading.Event) -> None:
    import multiprocessing as mp
    from multiprocessing.connection import wait

    if address is not None:
        raise ConfigError("--address applies to --engine ray only")
    ctx = mp.get_context("spawn")
    n = max(1, min(workers, len(arglist)))
    pending = list(range(len(arglist)))
    procs, conns, busy = [], [], {}
    try:
        for _ in range(n):
            parent, child = ctx.Pipe()
            p = ctx.Process(target=_worker_main, args=(child,), daemon=True)
            p.start()
            child.close()
            procs.append(p)
            conns.append(parent)

        def give(w: int) -> None:
            if pending:
                i = pending.pop(0)
                busy[w] = i
                conns[w].send((i, fn, arglist[i]))
            else:
                busy.pop(w, None)
                conns[w].send(None)

        for w in range(n):
            give(w)
        open_conns = set(range(n))
        while busy and not stopped.is_set():
            ready = wait([conns[w] for w in open_conns], timeout=0.2)
            for c in ready:
                w = conns.index(c)
                try:
                    msg = c.recv()
                except (EOFError, OSError):
                    open_conns.discard(w)
                    if w in busy:
                        procs[w].join(2.0)
                        raise JobFailed(str(WorkerLost(
                            f"the worker running {label(arglist[busy[w]])} ended without a "
                            f"result (exit status {procs[w].exitcode}): a domain that calls "
                            "halt/0 or crashes Prolog ends its worker; check it with relrl "
                            "check"))) from None
                    continue
                kind, index = msg[0], msg[1]
                if kind == "event":
                    event(index, msg[2])
                elif kind == "done":
                    outcome.results[index] = msg[2]
                    give(w)
                elif kind == "error":
                    raise JobFailed(msg[3])
                else:
                    raise JobCrashed(f"job {label(arglist[index])} failed with {msg[2]} "
                                     f"(a bug in relrl; the worker's traceback follows)\n"
                                     f"{msg[3]}")
    finally:
        for c in conns:
            try:
                c.close()
            except OSError:
                pass
        _stop_processes(procs)


#: engine name -> runner ``(fn, arglist, outcome, event, workers=, address=, label=,
#: stopped=)`` that fills ``outcome.results`` and calls ``event`` for every event.
ENGINES: dict[str, Callable[..., None]] = {"local": _run_local, "ray": run_ray}
