"""The Prolog side of a control step, measured alone (``relrl bench --prolog-step``).

``relrl bench`` times a whole step: the simulator, Python, one gateway call and the knowledge
work inside Prolog. To see (and profile) the Prolog part alone, :func:`record` runs the
bench's seeded interaction (an :class:`~relrl.loop.Agent` on the Social Interactive Simulator
with Experiment 1's caregiver: 500 warm-up steps, then the timed ones) and writes every
step's percepts, the index of the response emitted before it, its mode and what
``engine_step/6`` returned to a recording — Prolog terms, one a line. :func:`replay` runs
``prolog/stepbench.pl`` in plain ``swipl`` over it: the same domain, learner, parameters and
seed, one ``engine_step/6`` per recorded step, each checked against the recording (a
difference is an error), timed with and without the gateway's time-limited call, and, on
request, under SWI-Prolog's profiler.

Example:
    >>> from relrl.stepbench import bench_prolog_step
    >>> figures = bench_prolog_step("etg", steps=1000)
    >>> figures["direct"]["us_per_step"], figures["direct"]["inferences_per_step"]
"""

from __future__ import annotations

import json
import shutil
import subprocess
import tempfile
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from relrl.errors import RelrlError
from relrl.terms import format_term

__all__ = ["record", "replay", "bench_prolog_step"]


class _RecordingEngine:
    """Stands in for an agent's :class:`~relrl.engine.Engine`: passes every call on and
    writes each step (and each end of an episode) to ``sink``."""

    def __init__(self, engine: Any, sink: list[str]) -> None:
        self._engine = engine
        self._sink = sink

    def __getattr__(self, name: str) -> Any:
        return getattr(self._engine, name)

    def step_fields(self, percepts: Any, emitted: int = -1, mode: str = "learn",
                    want: Iterable[str] = ()) -> tuple:
        want = list(want)
        fields = self._engine.step_fields(percepts, emitted, mode, want)
        code, necessity, outputs, reward, reinforced, mask, action = fields[:7]
        value = getattr(percepts, "value", percepts)   # a Cached percept list
        expected = ("r", code, necessity, list(outputs), reward,
                    "true" if reinforced else "false", mask, action)
        self._sink.append(f"s({format_term(list(value))},{emitted},{mode},"
                          f"{format_term(expected)}).")
        return fields

    def step(self, percepts: Any, emitted: int = -1, mode: str = "learn",
             want: Iterable[str] = ()) -> Any:
        from relrl.engine import StepResult

        return StepResult(*self.step_fields(percepts, emitted, mode, want))

    def end_episode(self) -> None:
        self._engine.end_episode()
        self._sink.append("end_episode.")


def record(path: str | Path, learner: str = "etg", *, steps: int = 5000, warmup: int = 500,
           seed: int = 0, domain: str | Path | None = None) -> Path:
    """Run ``relrl bench``'s interaction for ``learner`` and write its recording to ``path``.

    Args:
        path: the recording to write.
        learner: a registered learner name.
        steps: timed steps (after the warm-up).
        warmup: steps before them (replayed untimed).
        seed: the agent's and the simulator's seed.
        domain: the domain file (default: Experiment 1's, examples/domains/sis.pl).
    """
    from relrl.experiments.sis import DEFAULT_DOMAIN
    from relrl.kb import KnowledgeBase
    from relrl.learners import make_learner
    from relrl.loop import Agent, Interaction
    from relrl.sim.caregiver import make_caregiver
    from relrl.sim.sis import SharedAttentionEnv

    domain = Path(domain if domain is not None else DEFAULT_DOMAIN).resolve()
    lines: list[str] = []
    with KnowledgeBase(domain) as kb:
        made = make_learner(learner)
        agent = Agent(kb, made, seed=seed)
        params = [("=", k, v) for k, v in made.params.items()]
        lines.append(f"stepbench({format_term(str(domain))},{format_term(made.engine_name)},"
                     f"{format_term(params)},{seed},{warmup}).")
        agent.engine = _RecordingEngine(agent.engine, lines)   # type: ignore[assignment]
        env = SharedAttentionEnv(make_caregiver("paper"), max_steps=None, record_trace=False)
        interaction = Interaction(env, agent)
        interaction.reset(seed=seed)
        interaction.run(warmup + steps, keep=False)
    from relrl.outdir import write_atomic

    return write_atomic(path, "\n".join(lines) + "\n")


def replay(path: str | Path, *, passes: int = 3, profile: bool = False, top: int = 25,
           timeout: float = 600.0) -> dict[str, Any]:
    """Replay a recording in plain ``swipl`` (``prolog/stepbench.pl``); return its figures.

    Raises:
        RelrlError: swipl is missing, or the replay failed (a step differed from the
            recording: the message says which and how).
    """
    from relrl.kb import PROLOG_DIR

    swipl = shutil.which("swipl")
    if swipl is None:
        raise RelrlError("swipl is not installed (make setup installs it)")
    argv: Sequence[str] = [swipl, "-q", "-g", "relrl_stepbench:stepbench_main", "-t", "halt",
                           str(PROLOG_DIR / "stepbench.pl"), "--", str(path),
                           f"--passes={passes}", f"--top={top}"]
    if profile:
        argv = [*argv, "--profile"]
    proc = subprocess.run(argv, capture_output=True, text=True, timeout=timeout)
    lines = proc.stdout.strip().splitlines()
    if proc.returncode != 0 or not lines:
        message = (proc.stderr.strip() or proc.stdout.strip() or "no output").splitlines()
        raise RelrlError(f"replaying {path} in swipl failed: {' '.join(message)[:2000]}")
    return json.loads(lines[-1])


def bench_prolog_step(learner: str = "etg", *, steps: int = 5000, warmup: int = 500,
                      seed: int = 0, passes: int = 3, profile: bool = False, top: int = 25
                      ) -> dict[str, Any]:
    """Record ``relrl bench``'s run of ``learner`` and replay it in plain swipl: the Prolog
    side of a step in microseconds and inferences (see :func:`replay`)."""
    with tempfile.TemporaryDirectory(prefix="relrl-stepbench-") as tmp:
        path = record(Path(tmp) / f"{learner}.pl", learner, steps=steps, warmup=warmup,
                      seed=seed)
        return replay(path, passes=passes, profile=profile, top=top)

