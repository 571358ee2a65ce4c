"""Running an experiment's independent jobs over local worker processes.

Each worker process holds one Prolog engine (pyswip allows one per process). Jobs report
their progress through a queue; the parent draws a progress bar when stderr is a terminal.
The design leaves room for a distributed engine (e.g. Ray) to call the same job function.
"""

from __future__ import annotations

import multiprocessing as mp
import queue as queue_mod
import sys
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
    """A one-line progress bar on a terminal; silent otherwise."""

    def __init__(self, total: int, stream: Any = None) -> None:
        self.total = total
        self.done = 0
        self.stream = sys.stderr if stream is None else stream  # the stderr of now
        self.active = bool(getattr(stream, "isatty", lambda: False)())

    def update(self, label: str) -> None:
        """One unit done."""
        self.done += 1
        if self.active:
            width = 30
            filled = int(width * self.done / max(1, self.total))
            self.stream.write(f"\r[{'#' * filled}{'.' * (width - filled)}] "
                              f"{self.done}/{self.total} {label:<40}")
            self.stream.flush()

    def close(self) -> None:
        """End the bar's line."""
        if self.active:
            self.stream.write("\n")
            self.stream.flush()


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
