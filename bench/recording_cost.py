"""``relrl bench``'s recording figure: a session's time units per second with ``--record``
against the same session with ``--out`` alone, paired on the simulator.

The session is the real one (:func:`relrl.episodes.run_episode`) of
:func:`bench.episode_script.fruits_episode`: the fruits domain, ETG, the protocol caregiver
with fruits, ``perception`` ``symbolic`` (the simulator's facts; no frames:
every time unit's channels are recorded, nothing else) or ``render`` (frames rendered and
perceived, recorded at the default ``--record-rate``). The loop's rate is timed from inside:
the session polls its word source once per time unit, and the bench's source notes the time.
Pairs run back to back in alternating order; the ratio is the median of the pairs' ratios.
The recording's encoding and writing run in a process of their own
(:mod:`relrl.recording.child`); its CPU time is reported beside the session's.
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

from bench.episode_script import fruits_episode

__all__ = ["bench_recording"]


class _Clock:
    """A word source that hears nothing and notes when each time unit began."""

    def __init__(self) -> None:
        self.first: tuple[float, float, float] | None = None
        self.last: tuple[float, float, float] | None = None
        self.calls = 0

    def poll(self) -> list[str]:
        now = (time.perf_counter(), time.thread_time(), time.process_time())
        if self.first is None:
            self.first = now
        self.last = now
        self.calls += 1
        return []

    def close(self) -> None:
        """Nothing to release."""


def _once(script: Path, out: Path | None, record: bool) -> dict[str, float]:
    import resource

    from relrl.episodes import RunOptions, load_episode, run_episode

    clock = _Clock()
    opts = RunOptions(out=out, plots=False, record=record, words=clock)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    run_episode(load_episode(script), opts)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)  # the writer process, waited for
    writer = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    units = clock.calls - 1
    (w0, c0, p0), (w1, c1, p1) = clock.first, clock.last
    size = (out / "session.mcap").stat().st_size if record else 0
    return {"units_per_second": units / (w1 - w0), "loop_cpu_us": 1e6 * (c1 - c0) / units,
            "process_cpu_us": 1e6 * (p1 - p0) / units, "mcap_bytes": size,
            "writer_cpu_us": 1e6 * writer / units,
            "units": units}


def bench_recording(steps: int = 3000, *, pairs: int = 6,
                    perception: str = "symbolic") -> dict[str, Any]:
    """Time units per second of a session with ``--out DIR --record`` against ``--out DIR``.

    Args:
        steps: time units per run.
        pairs: pairs of runs (alternating which runs first).
        perception: ``symbolic`` or ``render`` (frames at the default record rate).

    Returns:
        the medians of each kind, the median pair ratio (the target: at least 0.9), the
        control thread's and the session process's CPU time per unit, the writer process's
        (which runs beside the session, on another core when there is one), and the file's
        bytes per time unit.
    """
    from relrl.resources import example

    with tempfile.TemporaryDirectory(prefix="relrl-bench-rec-") as tmp:
        root = Path(tmp)
        script = root / "bench.toml"
        script.write_text(fruits_episode(example("domains/fruits.pl"), name="bench-recording",
                                         seed=3, steps=steps, perception=perception))
        plain, recorded = [], []
        for i in range(pairs):
            for rec in ((False, True) if i % 2 == 0 else (True, False)):
                out = root / f"run-{i}-{int(rec)}"
                (recorded if rec else plain).append(_once(script, out, rec))
    ratios = [r["units_per_second"] / p["units_per_second"]
              for p, r in zip(plain, recorded, strict=True)]

    def med(runs: list[dict[str, float]], key: str) -> float:
        return statistics.median(r[key] for r in runs)

    return {"perception": perception, "steps": steps, "pairs": pairs,
            "units_per_second_out": med(plain, "units_per_second"),
            "units_per_second_record": med(recorded, "units_per_second"),
            "ratio": statistics.median(ratios), "ratio_range": [min(ratios), max(ratios)],
            "loop_cpu_us_out": med(plain, "loop_cpu_us"),
            "loop_cpu_us_record": med(recorded, "loop_cpu_us"),
            "process_cpu_us_out": med(plain, "process_cpu_us"),
            "process_cpu_us_record": med(recorded, "process_cpu_us"),
            # the writer process's CPU over the whole run (its start-up included), per unit
            "writer_cpu_us_record": med(recorded, "writer_cpu_us"),
            "mcap_bytes_per_unit": med(recorded, "mcap_bytes") / steps}
