"""What a learning step costs as the world grows, measured in one process.

Speeds taken in separate processes, or one after the other, move with whatever else the
machine runs. :func:`step_cost_by_size` builds one agent per world size in the same process
(each with its generated domain and its own simulator), lets each learn a while so that its
knowledge has the size it will have, and then times *blocks* of learning steps, the sizes
taking turns block by block: a change of load touches every size alike, and the ratio of
two sizes' costs holds. The cost is the process's CPU time in the agent's step
(:meth:`relrl.loop.Agent.step`: percepts in, Python and Prolog, the response out); the
simulator's own step is timed apart.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

__all__ = ["step_cost_by_size"]


def step_cost_by_size(learner: str = "tg", sizes: tuple[int, ...] = (5, 129), *,
                      warmup: int = 3000, block: int = 500, blocks: int = 6,
                      seed: int = 0) -> dict[str, Any]:
    """CPU microseconds per learning step of ``learner`` in worlds of each of ``sizes``
    toy places, in one process, blocks alternating between the sizes.

    Returns ``{"sizes": {P: {"agent_cpu_us": ..., "env_cpu_us": ..., "positions": ...}},
    "ratio": {P: agent cost at P / agent cost at the smallest P}, ...}``.
    """
    from relrl.kb import KnowledgeBase
    from relrl.learners import make_learner
    from relrl.loop import Agent, Interaction
    from relrl.sim.sis import SharedAttentionEnv
    from relrl.sim.world import World

    if not sizes:
        raise ValueError("step_cost_by_size needs at least one size")
    with tempfile.TemporaryDirectory(prefix="relrl-sizes-") as tmp:
        runs = []
        try:
            for size in sizes:
                world = World(places=size)
                kb = KnowledgeBase(str(world.write_domain(Path(tmp))))
                run = {"size": size, "kb": kb, "agent": 0.0, "env": 0.0, "steps": 0}
                runs.append(run)
                agent = Agent(kb, make_learner(learner), seed=seed)
                interaction = Interaction(
                    SharedAttentionEnv(world=world, max_steps=None, record_trace=False), agent)
                interaction.reset(seed=seed)
                interaction.run(warmup, keep=False)
                run.update(interaction=interaction, agent_obj=agent)
            clock = time.process_time
            for _ in range(blocks):
                for run in runs:
                    interaction, agent = run["interaction"], run["agent_obj"]
                    info = interaction.info
                    agent_time = env_time = 0.0
                    for _ in range(block):
                        t0 = clock()
                        out = agent.step(info["percepts"])
                        t1 = clock()
                        info = interaction.env.step(out.action)[4]
                        env_time += clock() - t1
                        agent_time += t1 - t0
                    interaction.info = info
                    run["agent"] += agent_time
                    run["env"] += env_time
                    run["steps"] += block
            out_sizes = {str(r["size"]): {
                "agent_cpu_us": 1e6 * r["agent"] / r["steps"],
                "env_cpu_us": 1e6 * r["env"] / r["steps"],
                "positions": r["agent_obj"].learner.size()["positions"]} for r in runs}
        finally:
            for run in runs:
                run["kb"].close()
    base = out_sizes[str(sizes[0])]["agent_cpu_us"]
    return {"learner": learner, "warmup": warmup, "block": block, "blocks": blocks,
            "sizes": out_sizes,
            "ratio": {s: v["agent_cpu_us"] / base for s, v in out_sizes.items()}}
