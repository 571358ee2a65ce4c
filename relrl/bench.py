"""Benchmarks behind ``relrl bench``: rates and ratios, measured on this machine.

* the cost of one gateway call with one binding;
* steps per second of each learner driving the Social Interactive Simulator (a fixed,
  seeded synthetic environment), learning on, and the gateway calls per step;
* the Prolog side of an ETG step alone: the same seeded run recorded and replayed in plain
  swipl, every decision checked (``bench/stepbench.py``, a harness of the source tree: from an
  installed package without it this figure is skipped), CPU microseconds and inferences per
  step, called directly and through the gateway's guarded call;
* the simulator's own step rate;
* ETG's steps/s with the live web monitor attached, against without (bench/monitor_cost.py);
* a session's time units/s with ``--record`` (the MCAP file) against ``--out`` alone, paired
  (bench/recording_cost.py; skipped without the ``mcap`` extra);
* the perception pipeline's frames per second (bench/perception_speed.py), optional.

Targets (from the project's issues): ETG at most 1.5 gateway calls per step, and an ETG step
(the agent's step, Python and Prolog together: percepts in, response out) costing at most 3
gateway calls' worth of time, measured in the same run: the gateway call is timed right
before and right after each learner (their mean is that learner's ``gateway_call_us``), so
the ratio holds under whatever load the machine has; the top-level ``gateway_call_us`` is the
median of all those timings.
The interaction step (the agent's step and the simulator's) is reported beside it as
``interaction_step_in_gateway_calls``. The step rates are reported too (they move with
the load; the ratio much less). tg: at most 1.5 gateway calls per step, at least 3,000
steps/s, a step costing at most twice ETG's (the process's CPU time per interaction step),
and a learning step in a world of 129 toy places costing at most 1.5 times one in a
world of 5 (bench/world_size.py: one process, blocks alternating).
Perception: at least 60 fps on real photographs at 320x240 (full
search), with one thread and with two (wall clock, and on two free cores).
"""

from __future__ import annotations

import importlib.util
import statistics
import time
from pathlib import Path
from types import ModuleType
from typing import Any

from relrl.errors import ConfigError

__all__ = ["bench_engine", "bench_all", "measure_call_cost", "stepbench"]

#: The harness that replays a step's Prolog side in plain swipl: source tree only.
STEPBENCH = Path(__file__).resolve().parents[1] / "bench" / "stepbench.py"


def stepbench() -> ModuleType:
    """The source tree's harness of the Prolog side of a step (``bench/stepbench.py``).

    Raises:
        ConfigError: relrl runs from an installed package, without its source tree.
    """
    if not STEPBENCH.is_file():
        raise ConfigError(f"the Prolog side of a step is measured from relrl's source tree "
                          f"({STEPBENCH} is not part of the installed package): run relrl "
                          "from a checkout (pip install -e .)")
    spec = importlib.util.spec_from_file_location("relrl_stepbench", STEPBENCH)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def measure_call_cost(n: int = 2000) -> float:
    """Seconds per gateway call with one binding (``relrl_state:state_code``-sized work)."""
    from relrl.kb import KnowledgeBase
    from relrl.terms import Var

    with KnowledgeBase() as kb:
        goal = ":".join(kb.api_goal("wm_clock"))
        kb.call(goal, kb.module, Var())
        t0 = time.perf_counter()
        for _ in range(n):
            kb.call(goal, kb.module, Var())
        return (time.perf_counter() - t0) / n


def bench_engine(learner: str, steps: int = 5000, seed: int = 0) -> dict[str, float]:
    """Steps/s and gateway calls per step of ``learner`` on the SIS, learning on, and the
    process's CPU time per step (what the step costs this process, however loaded the
    machine is).

    The interaction step is the agent's step (:meth:`relrl.loop.Agent.step`: percepts in,
    Python and Prolog, response out) and the simulator's; both are timed in the same loop,
    the agent's step alone as ``agent_us_per_step``."""
    from relrl.experiments.sis import DEFAULT_DOMAIN
    from relrl.kb import KnowledgeBase, gateway_calls
    from relrl.learners import make_learner
    from relrl.loop import Agent, Interaction
    from relrl.sim.caregiver import make_caregiver
    from relrl.sim.sis import SharedAttentionEnv

    with KnowledgeBase(DEFAULT_DOMAIN) as kb:
        agent = Agent(kb, make_learner(learner), seed=seed)
        env = SharedAttentionEnv(make_caregiver("paper"),
                                 max_steps=None, record_trace=False)
        interaction = Interaction(env, agent)
        interaction.reset(seed=seed)
        interaction.run(500, keep=False)            # warm up: the tree and tables exist
        info = interaction.info
        assert info is not None
        clock, agent_time = time.perf_counter, 0.0
        calls0 = gateway_calls()
        c0 = time.process_time()
        t0 = clock()
        for _ in range(steps):                      # Interaction.run's loop, the agent timed
            t = clock()
            out = agent.step(info["percepts"])
            agent_time += clock() - t
            info = env.step(out.action)[4]
        elapsed = clock() - t0
        cpu = time.process_time() - c0
        calls = gateway_calls() - calls0
        return {"steps_per_second": steps / elapsed, "us_per_step": 1e6 * elapsed / steps,
                "agent_us_per_step": 1e6 * agent_time / steps,
                "cpu_us_per_step": 1e6 * cpu / steps,
                "gateway_calls_per_step": calls / steps, "steps": steps}


def bench_all(*, steps: int = 5000, perception: bool = True, faces: bool = True
              ) -> dict[str, Any]:
    """Every benchmark; a JSON-ready dict."""
    import os
    import platform

    from relrl import __version__
    from relrl.learners import DOMAINS, learners
    from relrl.machine import machine_info
    from relrl.sim.policies import bench_step_rate

    # "experiment" and "machine_info" make the file a run record ``relrl report`` renders
    out: dict[str, Any] = {"experiment": "bench", "relrl_version": __version__,
                           "python": platform.python_version(), "cpus": os.cpu_count(),
                           "machine_info": machine_info()}
    # Each learner's step is set against gateway calls timed right before and right after
    # it (their mean): a machine whose speed drifts during the run (other jobs, the clock)
    # moves both sides of each ratio together.
    out["learners"] = {}
    calls: list[float] = []
    for name in learners(DOMAINS):
        before = measure_call_cost(5000) * 1e6
        figures = bench_engine(name, steps)
        after = measure_call_cost(5000) * 1e6
        call = (before + after) / 2
        calls += [before, after]
        figures["gateway_call_us"] = call
        figures["step_in_gateway_calls"] = figures["agent_us_per_step"] / call
        figures["interaction_step_in_gateway_calls"] = figures["us_per_step"] / call
        out["learners"][name] = figures
    out["gateway_call_us"] = statistics.median(calls)
    tg, etg_ = out["learners"]["tg"], out["learners"]["etg"]
    # what a step costs this process (its CPU time), tg's against ETG's: the wall-clock
    # figures move with whatever else the machine runs while one learner or the other is timed
    out["tg_step_in_etg_steps"] = tg["cpu_us_per_step"] / etg_["cpu_us_per_step"]
    from bench.world_size import step_cost_by_size

    out["tg_step_by_size"] = step_cost_by_size("tg", (5, 129), warmup=min(3000, 10 * steps),
                                               block=max(50, steps // 10), blocks=6)
    try:
        replayed = stepbench().bench_prolog_step("etg", steps=steps)
    except ConfigError as exc:
        out["etg_prolog_side"] = {"skipped": str(exc)}
    else:
        out["etg_prolog_side"] = {
            "steps": replayed["steps"], "passes": replayed["passes"],
            "cpu_us_per_step": replayed["direct"]["cpu_us_per_step"],
            "inferences_per_step": replayed["direct"]["inferences_per_step"],
            "gateway_cpu_us_per_step": replayed["gateway"]["cpu_us_per_step"],
            "in_gateway_calls": replayed["direct"]["cpu_us_per_step"] / out["gateway_call_us"]}
    out["sis_env_steps_per_second"] = bench_step_rate(200_000, record_trace=False)
    from bench.monitor_cost import bench_monitor

    out["monitor"] = bench_monitor(steps)   # ETG steps/s with the live monitor / without
    try:  # a session's time units/s recording MCAP / with the trace alone
        from bench.recording_cost import bench_recording

        out["recording"] = bench_recording(min(steps, 3000), pairs=6 if steps >= 1000 else 2)
    except ImportError as exc:  # pragma: no cover - the mcap extra missing
        out["recording"] = {"skipped": str(exc)}
    if perception:
        try:
            from bench import perception_speed

            out["perception"] = perception_speed.bench(faces=faces)
        except ImportError as exc:  # pragma: no cover - OpenCV missing
            out["perception"] = {"skipped": str(exc)}
    etg = out["learners"]["etg"]
    out["targets"] = {
        "etg_calls_per_step<=1.5": etg["gateway_calls_per_step"] <= 1.5,
        "etg_step<=3_gateway_calls": etg["step_in_gateway_calls"] <= 3.0,
        "tg_calls_per_step<=1.5": out["learners"]["tg"]["gateway_calls_per_step"] <= 1.5,
        "tg_steps_per_second>=3000": out["learners"]["tg"]["steps_per_second"] >= 3000,
        "tg_step<=2x_etg_step": out["tg_step_in_etg_steps"] <= 2.0,
        "tg_step_P129<=1.5x_P5": out["tg_step_by_size"]["ratio"]["129"] <= 1.5,
        "monitor_steps_ratio>=0.9": out["monitor"]["ratio"] >= 0.9,
    }
    if "ratio" in out["recording"]:
        out["targets"]["recording_units_ratio>=0.9"] = out["recording"]["ratio"] >= 0.9
    photos = out.get("perception", {}).get("fps_photos_320x240_cold")
    if photos is not None:  # issue 13: real photos, full search, one OpenCV thread
        out["targets"]["perception_photos_320x240_fps>=60"] = photos >= 60
    for key, line in (("fps_photos_320x240_cold_2threads", "2threads_fps"),
                      ("free_cores_fps_photos_320x240_cold_2threads", "2threads_free_cores_fps")):
        fps = out.get("perception", {}).get(key)  # the same with two perception threads
        if fps is not None:
            out["targets"][f"perception_photos_320x240_{line}>=60"] = fps >= 60
    return out
