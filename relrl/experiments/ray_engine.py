"""The ``ray`` engine: an experiment's jobs as Ray tasks (``pip install 'relrl[ray]'``).

Each job becomes one task asking for one CPU; a job's random streams are seeded from its
arguments alone, so a task gives the same result on any node, and ``results.json`` is
byte-identical to a local run with the same seeds. Progress events travel through a Ray
queue actor. ``address=None`` starts a private local Ray instance with ``workers`` CPUs (shut
down at the end); an address (``ray://head:10001``, ``HOST:6379`` or ``auto``) joins an
existing cluster, whose nodes need relrl (with its Debian SWI-Prolog) installed. A worker
that dies, a job's relrl error and Ctrl-C behave as with local workers
(:mod:`relrl.experiments.runner`).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from relrl.errors import ConfigError, JobCrashed, JobFailed

__all__ = ["run_ray"]


def _task(fn: Callable[..., dict[str, Any]], args: tuple, index: int, queue: Any
          ) -> tuple[Any, ...]:
    """The body of one Ray task: run the job, ship its events, never raise a relrl error."""
    import traceback

    from relrl.errors import RelrlError

    def report(ev: dict[str, Any]) -> None:
        queue.put_nowait((index, ev))

    try:
        return ("done", fn(*args, report=report))
    except RelrlError as exc:
        return ("error", type(exc).__name__, str(exc))
    except Exception as exc:  # noqa: BLE001 - a bug: ship its traceback to the driver
        return ("crash", type(exc).__name__, "".join(traceback.format_exception(exc)))


def _check_reachable(address: str, timeout: float = 3.0) -> None:
    """Fail at once, in one line, when a ``HOST:PORT`` (or ``ray://HOST:PORT``) address does
    not answer (Ray itself retries for minutes, printing warnings)."""
    import socket

    target = address.removeprefix("ray://")
    host, sep, port = target.rpartition(":")
    if not sep or not port.isdigit() or not host:
        if address == "auto":
            return
        raise ConfigError(f"--address {address!r}: use HOST:PORT, ray://HOST:PORT or auto")
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
            pass
    except OSError as exc:
        raise ConfigError(f"--address {address}: no Ray cluster answers there "
                          f"({exc.strerror or exc})") from None


def _connect(ray: Any, address: str | None, workers: int) -> bool:
    """Start or join Ray; returns True when this call started it (and must stop it)."""
    if address is not None:
        _check_reachable(address)
    if ray.is_initialized():
        return False
    import os

    # a quiet start: no usage-statistics upload, only Ray's own errors on stderr
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    os.environ.setdefault("RAY_BACKEND_LOG_LEVEL", "error")
    options: dict[str, Any] = {"include_dashboard": False, "logging_level": "ERROR",
                               "log_to_driver": False}
    if address is None:
        options.update(num_cpus=workers, _system_config={"metrics_report_interval_ms": 0})
    try:
        ray.init(address=address, **options)
    except (ConnectionError, ValueError, RuntimeError, TimeoutError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ConfigError(f"--address {address}: cannot join a Ray cluster there ({first})") \
            from None
    return True


def run_ray(fn: Callable[..., dict[str, Any]], arglist: list[tuple], outcome: Any,
            event: Callable[[int, dict[str, Any]], None], *, workers: int,
            address: str | None, label: Callable[[tuple], str],
            stopped: threading.Event) -> None:
    """Run the jobs as Ray tasks, filling ``outcome.results`` (see
    :func:`relrl.experiments.runner.run_jobs`)."""
    try:
        import ray
        from ray.util.queue import Empty, Queue
    except ImportError:
        raise ConfigError("--engine ray needs Ray: pip install 'relrl[ray]'") from None

    started = _connect(ray, address, workers)
    queue = None
    pending: list[Any] = []
    try:
        queue = Queue(actor_options={"num_cpus": 0})
        remote = ray.remote(num_cpus=1, max_retries=0)(_task)
        refs = {remote.remote(fn, args, i, queue): i for i, args in enumerate(arglist)}
        pending = list(refs)

        def drain() -> None:
            while True:
                try:
                    batch = queue.get_nowait_batch(queue.qsize()) if queue.qsize() else []
                except Empty:
                    return
                if not batch:
                    return
                for index, ev in batch:
                    event(index, ev)

        while pending and not stopped.is_set():
            done, pending = ray.wait(pending, num_returns=1, timeout=0.2)
            drain()
            for ref in done:
                index = refs[ref]
                try:
                    status = ray.get(ref)
                except ray.exceptions.RayError as exc:
                    first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
                    raise JobFailed(f"the Ray task running {label(arglist[index])} ended "
                                     f"without a result ({type(exc).__name__}: {first}); a "
                                     "domain that calls halt/0 or crashes Prolog ends its "
                                     "worker: check it with relrl check") from None
                if status[0] == "done":
                    outcome.results[index] = status[1]
                elif status[0] == "error":
                    raise JobFailed(status[2])
                else:
                    raise JobCrashed(f"job {label(arglist[index])} failed with {status[1]} "
                                     f"(a bug in relrl; the task's traceback follows)\n"
                                     f"{status[2]}")
        drain()
    finally:
        for ref in pending:
            try:
                ray.cancel(ref, force=True)
            except Exception:  # noqa: BLE001 - best effort while stopping
                pass
        if queue is not None:
            try:
                queue.shutdown(force=True)
            except Exception:  # noqa: BLE001 - best effort while stopping
                pass
        if started:
            ray.shutdown()
