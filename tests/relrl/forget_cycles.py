"""Create, step and drop a knowledge base many times with each learner, in one process;
print, per learner, the process's resident memory after each cycle and what is left in
Prolog of the dropped knowledge bases (run by tests/relrl/test_forget.py in a process of
its own; ``python -m tests.relrl.forget_cycles CYCLES STEPS LEARNER...`` for the figures).
"""

from __future__ import annotations

import json
import sys
import time

from relrl.kb import KnowledgeBase
from relrl.learners import make_learner, make_world_learner
from relrl.loop import Agent
from relrl.worlds.world import World
from tests.conftest import ROOT

SIS = ROOT / "examples" / "domains" / "sis.pl"
BLOCKS = ROOT / "examples" / "worlds" / "blocks.pl"
PERCEPTS = [
    [("see", "face"), ("pose", "face", "frontal"), ("hear", "attention"), ("at", "centre")],
    [("see", "face"), ("pose", "face", "right_down"), ("at", "centre")],
    [("see", "face"), ("pose", "face", "left"), ("at", "left")],
]

#: What is left of the dropped knowledge base {kb}: the module itself, globals named after
#: it (nb_current/2), and clauses of relrl's modules that name it.
LEFT = ("(current_module('{kb}') -> M = [module] ; M = []), "
        "findall(K, (nb_current(K, _), atom(K), sub_atom(K, _, _, _, '{kb}')), Gs), "
        "findall(Mod:N/A-C, (current_module(Mod), sub_atom(Mod, 0, _, _, relrl_), "
        "Mod \\== '{probe}', current_predicate(Mod:N/A), functor(H, N, A), "
        "\\+ predicate_property(Mod:H, imported_from(_)), predicate_property(Mod:H, dynamic), "
        "aggregate_all(count, (clause(Mod:H, B), sub_term(X, H-B), X == '{kb}'), C), C > 0), "
        "Cs)")


def rss_kb() -> int:
    """The process's resident set size in KiB."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS in /proc/self/status")


def cycle(learner: str, steps: int) -> str:
    """One knowledge base made, stepped ``steps`` times (or a world's ``steps`` episodes)
    and dropped; returns its module's name."""
    if learner.endswith("-world"):
        with World(BLOCKS) as world:
            world.attach(make_world_learner(learner.split("-")[0]), seed=0)
            world.episodes(world.task_names()[0], [3], steps)
            return world.kb.module
    with KnowledgeBase(SIS) as kb:
        agent = Agent(kb, make_learner(learner), seed=0)
        for i in range(steps):
            agent.step(PERCEPTS[i % 3])
        agent.engine.keep()   # a kept snapshot, dropped with the knowledge base
        return kb.module


def measure(probe: KnowledgeBase, learner: str, cycles: int, steps: int) -> dict:
    """``cycles`` cycles of ``learner``: RSS after each, what is left, the time taken."""
    rss, module = [], ""
    start = time.perf_counter()
    for _ in range(cycles):
        module = cycle(learner, steps)
        rss.append(rss_kb())
    seconds = time.perf_counter() - start
    (solution,), _ = probe.query(LEFT.format(kb=module, probe=probe.module), max_solutions=1)
    left = {name: printed for name, _, printed in solution}
    return {"learner": learner, "cycles": cycles, "steps": steps, "seconds": round(seconds, 2),
            "module": module, "rss_kb": rss, "left_module": left["M"],
            "left_globals": left["Gs"], "left_clauses": left["Cs"]}


def main(cycles: int, steps: int, learners: list[str]) -> None:
    """One JSON line per learner on standard output."""
    with KnowledgeBase() as probe:   # open throughout, as a long-lived worker's other KB
        for learner in learners:
            print(json.dumps(measure(probe, learner, cycles, steps)), flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]), sys.argv[3:])
