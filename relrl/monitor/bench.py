"""``relrl bench``'s monitor figure: the control loop's steps/s with the live monitor
attached (server running, a browser-like client reading the event stream in another
process) against without, on the same seeded simulator run."""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from typing import Any

__all__ = ["bench_monitor"]

_CLIENT = """
import sys, urllib.request
r = urllib.request.urlopen(sys.argv[1] + "api/events")
n = 0
for line in r:
    n += len(line)
"""


def _rate(learner: str, steps: int, seed: int, on_step: Any = None) -> tuple[float, float]:
    """Steps per wall-clock second, and CPU microseconds per step of this thread."""
    from relrl.experiments.sis import DEFAULT_DOMAIN
    from relrl.kb import KnowledgeBase
    from relrl.learners import make_learner
    from relrl.loop import Agent, Interaction
    from relrl.sim.caregiver import make_caregiver
    from relrl.sim.sis import SharedAttentionEnv

    with KnowledgeBase(DEFAULT_DOMAIN) as kb:
        agent = Agent(kb, make_learner(learner), seed=seed)
        env = SharedAttentionEnv(make_caregiver("paper"),
                                 max_steps=None, record_trace=False)
        tap = on_step(agent) if on_step is not None else None
        want = tap.want if tap is not None else tuple
        interaction = Interaction(env, agent, on_step=tap)
        interaction.reset(seed=seed)
        for _ in range(500):  # warm up: the tree exists
            interaction.run(1, keep=False, want=want())
        t0, c0 = time.perf_counter(), time.thread_time()
        for _ in range(steps):  # one time unit at a time, as a session runs
            interaction.run(1, keep=False, want=want())
        return steps / (time.perf_counter() - t0), 1e6 * (time.thread_time() - c0) / steps


def bench_monitor(steps: int = 5000, *, learner: str = "etg", rate: float = 10.0,
                  repeats: int = 6, seed: int = 0) -> dict[str, Any]:
    """Steps/s of ``learner`` on the simulator without and with the monitor.

    ``repeats`` pairs of runs, the two runs of a pair back to back (in alternating order), so
    that both see the same load on a shared machine; the ratio is the median of the pairs'
    ratios (the target: at least 0.9), the rates the medians of each kind; and the control
    thread's CPU time per step with and without (which the machine's load does not change).
    """
    from relrl.monitor import Hub, start_live
    from relrl.monitor.tap import LoopTap

    hub = Hub(rate)
    server = start_live(hub)
    client = subprocess.Popen([sys.executable, "-c", _CLIENT, server.url],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        without, with_monitor = [], []
        for i in range(repeats):
            for monitored in ((False, True) if i % 2 == 0 else (True, False)):
                if monitored:
                    with_monitor.append(_rate(learner, steps, seed,
                                              lambda a: LoopTap(hub, a)))
                else:
                    without.append(_rate(learner, steps, seed))
    finally:
        client.kill()
        client.wait()
        server.close()
    ratios = [b[0] / a[0] for a, b in zip(without, with_monitor, strict=True)]
    return {"learner": learner, "steps": steps, "rate_hz": rate, "pairs": repeats,
            "steps_per_second_without": statistics.median(r for r, _ in without),
            "steps_per_second_with": statistics.median(r for r, _ in with_monitor),
            "ratio": statistics.median(ratios),
            # the control thread's own CPU time per step: what the monitor costs the loop,
            # whatever the load of a shared machine
            "cpu_us_per_step_without": statistics.median(c for _, c in without),
            "cpu_us_per_step_with": statistics.median(c for _, c in with_monitor),
            "ratio_range": [min(ratios), max(ratios)], "views_published": hub.version}
