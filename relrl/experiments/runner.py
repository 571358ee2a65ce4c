"""Running an experiment's independent jobs over local worker processes.

Each worker process holds one Prolog engine (pyswip allows one per process). Jobs report
their progress through a queue; the parent shows it (relrl.progress: a bar with ETA on a
terminal, log lines elsewhere).
The design leaves room for a distributed engine (e.g. Ray) to call the same job function.
"""

from __future__ import annotations

import multiprocessing as mp
import queue as queue_mod
import threading
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from typing import Any

__all__ = ["run_jobs", "ProgressBar"]

_progress_queue: Any = None


def _init_worker(q: Any) -> None:
    global _progress_queue
    _progress_queue = q


def _report(*item: Any) -> None:
    if _progress_queue is not None:
        _progress_queue.put(item)


def _call(job: Callable[..., dict[str, Any]], args: tuple) -> dict[str, Any]:
    args = tuple(_report if a is None and i == 3 else a for i, a in enumerate(args))
    return job(*args)


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

    def update(self, label: str) -> None:
        """One unit done (``label`` says which)."""
        self._progress.set_description(label)
        self._progress.update(1)

    def close(self) -> None:
        """End the bar."""
        self._progress.close()


def run_jobs(job: Callable[..., dict[str, Any]], arglist: list[tuple], *, workers: int,
             units_per_job: int) -> list[dict[str, Any]]:
    """Run ``job(*args)`` for every args tuple, with the progress callback put in place of
    the ``None`` at position 3; results in input order.

    ``workers`` <= 1 runs in this process (one Prolog engine here); more uses that many
    spawned worker processes.
    """
    bar = ProgressBar(units_per_job * len(arglist))

    def label(item: tuple) -> str:
        name, seed, point = item
        return f"{name} seed {seed} point {point}"

    try:
        if workers <= 1 or len(arglist) == 1:
            def report(*item: Any) -> None:
                bar.update(label(item))

            return [job(*(report if a is None and i == 3 else a for i, a in enumerate(args)))
                    for args in arglist]
        ctx = mp.get_context("spawn")
        q = ctx.Queue()
        stop = threading.Event()

        def drain() -> None:
            while not stop.is_set():
                try:
                    bar.update(label(q.get(timeout=0.2)))
                except queue_mod.Empty:
                    continue

        reader = threading.Thread(target=drain, daemon=True)
        reader.start()
        try:
            with ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                                     initializer=_init_worker, initargs=(q,)) as pool:
                futures = [pool.submit(_call, job, args) for args in arglist]
                return [f.result() for f in futures]
        finally:
            stop.set()
            reader.join()
    finally:
        bar.close()
