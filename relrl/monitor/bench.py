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


def _rate(learner: str, steps: int, seed: int, on_step: Any = None) -> float:
    from relrl.experiments.sis import DEFAULT_DOMAIN
    from relrl.kb import KnowledgeBase
    from relrl.learners import make_learner
    from relrl.loop import Agent, Interaction
    from relrl.sim.caregiver import make_caregiver
    from relrl.sim.sis import SharedAttentionEnv

    with KnowledgeBase(DEFAULT_DOMAIN) as kb:
        agent = Agent(kb, make_learner(learner), seed=seed)
        env = SharedAttentionEnv(make_caregiver("paper", {"attention_during_gaze": True}),
                                 max_steps=None, record_trace=False)
        tap = on_step(agent) if on_step is not None else None
        want = tap.want if tap is not None else tuple
        interaction = Interaction(env, agent, on_step=tap)
        interaction.reset(seed=seed)
        for _ in range(500):  # warm up: the tree exists
            interaction.run(1, keep=False, want=want())
        t0 = time.perf_counter()
        for _ in range(steps):  # one time unit at a time, as a session runs
            interaction.run(1, keep=False, want=want())
        return steps / (time.perf_counter() - t0)


def bench_monitor(steps: int = 5000, *, learner: str = "etg", rate: float = 10.0,
                  repeats: int = 3, seed: int = 0) -> dict[str, Any]:
    """Steps/s of ``learner`` on the simulator without and with the monitor, interleaved
    ``repeats`` times; the medians and their ratio (the target: at least 0.9)."""
    from relrl.monitor import Hub, start_live
    from relrl.monitor.tap import LoopTap

    hub = Hub(rate)
    server = start_live(hub)
    client = subprocess.Popen([sys.executable, "-c", _CLIENT, server.url],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        without, with_monitor = [], []
        for _ in range(repeats):
            without.append(_rate(learner, steps, seed))
            with_monitor.append(_rate(learner, steps, seed, lambda a: LoopTap(hub, a)))
    finally:
        client.kill()
        client.wait()
        server.close()
    a, b = statistics.median(without), statistics.median(with_monitor)
    return {"learner": learner, "steps": steps, "rate_hz": rate,
            "steps_per_second_without": a, "steps_per_second_with": b, "ratio": b / a,
            "views_published": hub.version}
