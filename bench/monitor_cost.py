"""``relrl bench``'s monitor figure: the control loop's steps/s with the live monitor
attached (server running, a browser-like client reading the event stream in another
process) against without, on the same seeded simulator run; and
:func:`bench_under_attack`, the same loop's steps/s while a client on loopback attacks the
monitor, with the server in a thread of the robot's process and in a process of its own (the
measurement that chose the second; docs/monitor.md)."""

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


#: a slowloris client: COUNT connections that send a request line and one header, then a
#: header line every quarter second and never the blank line, for SECONDS; with REOPEN a
#: connection the server closed is opened again. Prints ``opened N`` once they are made and,
#: at the end, ``answered A closed C``: A the connections the server answered (a 503 or a
#: 408), C those it closed. Arguments: PORT COUNT SECONDS [REOPEN].
SLOWLORIS = r"""
import socket, sys, time
port, count, seconds = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
reopen = len(sys.argv) > 4 and sys.argv[4] == "reopen"
def connect():
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=2)
        s.sendall(b"GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\n")
        s.setblocking(False)
        return s
    except OSError:
        return None
socks = [s for s in (connect() for _ in range(count)) if s is not None]
print("opened", len(socks), flush=True)
answered, closed, live = 0, 0, list(socks)
end = time.monotonic() + seconds
while time.monotonic() < end and (live or reopen):
    time.sleep(0.25)
    for s in list(live):
        try:
            data = s.recv(4096)
        except BlockingIOError:
            data = None
        except OSError:
            data = b""
        if data is None:
            try:
                s.send(b"X-a: b\r\n")
                continue
            except OSError:
                data = b""
        answered += bool(data)
        closed += 1
        live.remove(s)
        s.close()
    while reopen and len(live) < count and (s := connect()) is not None:
        live.append(s)
print("answered", answered, "closed", closed, flush=True)
"""
#: a request flood: one request after another on a fresh connection (reset, not closed, so
#: no port waits in TIME_WAIT), as fast as one process can. Arguments: PORT.
FLOOD = r"""
import socket, struct, sys, time
port = int(sys.argv[1])
while True:
    try:
        c = socket.create_connection(("127.0.0.1", port), timeout=5)
        c.sendall(b"GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        c.recv(65536)
        c.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        c.close()
    except OSError:
        time.sleep(0.01)
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


def bench_under_attack(attack: str = "flood", steps: int = 3000, *, pairs: int = 4,
                       rate: float = 10.0, seed: int = 0) -> dict[str, Any]:
    """ETG's steps/s on the simulator with the live monitor, without and with an attacker on
    loopback, for the server in a thread of this process (``thread``) and in a process of
    its own (``process``, what ``relrl run --monitor`` uses).

    ``attack`` is ``"flood"`` (:data:`FLOOD`) or ``"slowloris"`` (:data:`SLOWLORIS`, 300
    connections, reopened when closed). For each server, ``pairs`` pairs of runs, without
    and with the attack back to back in alternating order, a browser-like client reading
    the event stream throughout; the ratio (with / without) is the median of the pairs'.
    """
    from relrl.monitor import Hub
    from relrl.monitor.live import LiveServer
    from relrl.monitor.server import LiveSource, MonitorServer
    from relrl.monitor.tap import LoopTap

    if attack not in ("flood", "slowloris"):
        raise ValueError(f"attack must be flood or slowloris, not {attack!r}")
    args = [FLOOD] if attack == "flood" else [SLOWLORIS, "300", "3600", "reopen"]
    out: dict[str, Any] = {"attack": attack, "steps": steps, "pairs": pairs}
    for where in ("thread", "process"):
        hub = Hub(rate)
        server = (MonitorServer(LiveSource(hub)) if where == "thread" else LiveServer(hub))
        server.start()
        client = subprocess.Popen([sys.executable, "-c", _CLIENT, server.url],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        ratios, quiet, loud = [], [], []
        try:
            for i in range(pairs):
                got = {}
                for attacked in ((False, True) if i % 2 == 0 else (True, False)):
                    attacker = subprocess.Popen(
                        [sys.executable, "-c", args[0], str(server.port), *args[1:]],
                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) \
                        if attacked else None
                    try:
                        if attacker is not None:
                            time.sleep(1.0)  # the attack is under way
                        got[attacked] = _rate("etg", steps, seed, lambda a, h=hub: LoopTap(h, a))
                    finally:
                        if attacker is not None:
                            attacker.kill()
                            attacker.wait()
                quiet.append(got[False])
                loud.append(got[True])
                ratios.append(got[True][0] / got[False][0])
        finally:
            client.kill()
            client.wait()
            server.close()
        out[where] = {"steps_per_second_without": statistics.median(r for r, _ in quiet),
                      "steps_per_second_with": statistics.median(r for r, _ in loud),
                      "ratio": statistics.median(ratios),
                      "ratio_range": [min(ratios), max(ratios)],
                      "cpu_us_per_step_without": statistics.median(c for _, c in quiet),
                      "cpu_us_per_step_with": statistics.median(c for _, c in loud)}
    return out
