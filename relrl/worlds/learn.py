"""Learning a task of a world: a learning curve, evaluation on other sizes, memory, speed.

:func:`learn_task` is the one procedure behind ``relrl learn`` and every job of ``relrl
experiment worlds``: a learner learns ``episodes`` episodes of a task on the training sizes,
in blocks of ``block`` episodes; after each block the greedy policy (no learning, no
exploration) is evaluated on ``eval_episodes`` episodes of the training sizes, and at the
end on each test size — where the policy acts with no further learning. With R ``restarts``
above 0, the learned policy is checked at the end on ``check_episodes`` greedy episodes of the
training sizes (at most ``episodes``): a tree whose greedy choice wastes a move there (or
misses the goal) is set aside and a fresh learner learns the task again from nothing, from a
random stream of its own, up to R times; the first attempt that acts optimally in every
check episode is kept, or else the first attempt. A tree grows by greedy
splits it never revises, and the order of its first splits decides how it acts far beyond
its training sizes; a tree that already wastes moves on its training sizes is the one that
fails there (docs/worlds.md, Restarts). Evaluation draws its start states from a random
stream of its own, seeded from the run's seed and the evaluation point
(:func:`evaluation_seed`), and learning from the learner's stream alone: the learned policy
is the same whatever ``eval_episodes``, the test sizes and ``block`` are. Every evaluation
episode's optimal number of steps comes from the world (optimal_steps/3, else a breadth-
first search), so a score is a fraction of optimal: optimal / steps per episode, 0 for an
episode that missed the goal within the step bound (RRL's "percentage of optimal").

Speed is measured inside the job: learning steps per second (wall clock of the learning
batches, each one crossing into Prolog), the cost of a learning step at each size (CPU
time of blocks of learning episodes at each size from the same saved policy, sizes
alternating, the median of five rounds; its growth as a log-log slope), and one episode
per crossing against a batch per crossing (the shape: how much the crossings cost).
"""

from __future__ import annotations

import hashlib
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from relrl.outdir import write_atomic
from relrl.worlds.world import RULE_SECONDS, World, score

__all__ = ["LearnConfig", "evaluation_seed", "learn_task", "restart_seed", "step_cost_by_size"]


@dataclass
class LearnConfig:
    """What one learning run is: the world, task, learner, sizes, budget and seed."""

    world: str                              #: the world file
    task: str = "stack"                     #: a task of the world (its name or an instance)
    learner: str = "tg"
    params: dict[str, float] = field(default_factory=dict)
    train_sizes: list[int] = field(default_factory=lambda: [3, 4, 5])
    test_sizes: list[int] = field(default_factory=lambda: [6, 8, 10])
    episodes: int = 1000                    #: learning episodes
    block: int = 100                        #: learning episodes between evaluations
    eval_episodes: int = 100                #: greedy episodes per evaluation (per test size)
    seed: int = 0
    updates: str = "episode"                #: episode (RRL's) or online
    speed: bool = True                      #: measure the step cost by size and the shape
    rule_seconds: float = RULE_SECONDS      #: how long a rule of the world may run
    cost_sizes: list[int] = field(default_factory=list)   #: default: train + test sizes
    restarts: int = 3                       #: fresh attempts after a failed check (module doc)
    check_episodes: int = 1000              #: an attempt's check (at most ``episodes``)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return asdict(self)


def learn_task(config: LearnConfig, *, report: Callable[[dict[str, Any]], None] | None = None,
               policy_out: str | Path | None = None, policy_in: str | Path | None = None,
               traces: int = 0, monitor: Any = None,
               stop: Callable[[], bool] | None = None) -> dict[str, Any]:
    """Learn ``config.task`` and evaluate it; returns a JSON-ready dict.

    Args:
        config: the run.
        report: called with ``{"kind": "point", "entry": ...}`` after each evaluation.
        policy_out: save the learned policy there (readable Prolog), before each
            evaluation: whatever happens during one, the policy learned so far is kept.
        policy_in: start from this saved policy instead of from nothing.
        traces: keep this many greedy episodes of each test size with every step's state
            (for replay).
        monitor: a live monitor's :class:`~relrl.monitor.hub.Hub`: after each evaluation it
            is given the progress (status), the curve (one point of the plot per
            evaluation: the fraction of optimal), the learned tree and the first greedy
            episode's last state; the evaluation's episodes are the same with or without it.
        stop: asked between two crossings into Prolog; True stops the run (a stop signal,
            which also interrupts the crossing that is running).

    The result holds ``curve`` (one entry per evaluation), ``test`` (per test size),
    ``memory``, ``timing`` (wall-clock figures; the caller keeps them out of results.json)
    and, with ``traces``, ``traces``.

    Raises:
        KeyboardInterrupt: stopped (a signal, or ``stop``).
        RelrlError: a rule of the world failed, ran past its time limit ...
        Either carries ``partial``: the result so far, marked ``"partial": true`` --
        every evaluation point and test size that finished -- whose ``policy_episodes``
        says which policy ``policy_out`` holds (the one saved before the evaluation that
        was running).
    """
    from relrl.errors import RelrlError

    with World(config.world, rule_seconds=config.rule_seconds) as world, \
            tempfile.TemporaryDirectory(prefix="relrl-world-") as tmp:
        run = _Run(config, world, Path(tmp) / "policy.pl", policy_out, stop)
        try:
            return run.learn(report, policy_in, traces, monitor)
        except (KeyboardInterrupt, RelrlError) as exc:
            exc.partial = run.partial(exc)  # type: ignore[attr-defined]
            raise


class _Run:
    """One :func:`learn_task` run and what it has done so far (for a partial result)."""

    def __init__(self, config: LearnConfig, world: World, saved: Path,
                 policy_out: str | Path | None, stop: Callable[[], bool] | None) -> None:
        self.config, self.world, self.saved = config, world, saved
        self.policy_out, self.stop = policy_out, stop
        self.curve: list[dict[str, Any]] = []
        self.test: dict[str, Any] = {}
        self.kept: dict[str, list[dict[str, Any]]] = {}
        self.eval_cost: dict[str, dict[str, Any]] = {}
        self.memory: dict[str, Any] = {}
        self.learn_seconds, self.learn_steps, self.done = 0.0, 0, 0
        self.policy_episodes: int | None = None     # learning episodes of the saved policy
        self.attempt, self.attempt_done = 0, 0      # the attempt learning, its episodes
        self.attempts: list[dict[str, Any]] = []    # each checked attempt
        self.kept_attempt: tuple[int, Path] | None = None   # its number and policy file

    def _go_on(self) -> None:
        """Stop here when a stop was asked for."""
        if self.stop is not None and self.stop():
            raise KeyboardInterrupt

    def _keep_policy(self) -> None:
        """Save the policy as learned so far (to ``policy_out`` too), before an evaluation."""
        config = self.config
        header = (f"relrl policy: {config.learner} learner, world {Path(config.world).name}, "
                  f"task {config.task}")
        if self.attempt:
            header += f", restart {self.attempt} (seed {self._seed(self.attempt)})"
        if self.attempt_done < config.episodes:
            header += f" (after {self.attempt_done} of {config.episodes} learning episodes)"
        self._go_on()
        self.world.save_policy(self.saved, header)
        if self.kept_attempt is None:   # (else policy_out keeps the kept attempt)
            self._publish(self.saved)
            self.policy_episodes = self.attempt_done

    def _publish(self, path: Path) -> None:
        """Write the policy in ``path`` to ``policy_out``."""
        if self.policy_out is not None:
            write_atomic(self.policy_out, path.read_text(encoding="utf-8"))

    def _seed(self, attempt: int) -> int:
        """The learner's seed of ``attempt`` (0: the run's own)."""
        return restart_seed(self.config.seed, attempt) if attempt else self.config.seed

    def _check(self, task: Any, report: Callable[[dict[str, Any]], None] | None) -> bool:
        """Check the attempt's policy on its own greedy episodes of the training sizes;
        keep it when it is the first or acted optimally in every episode (True: no restart
        needed)."""
        config, k = self.config, self.attempt
        self._go_on()
        # (at most one check episode per learning episode: a check never costs more than
        # the learning it checks)
        eps = self.world.episodes(task, config.train_sizes,
                                  min(config.check_episodes, config.episodes), "greedy",
                                  optimal=True, seed=evaluation_seed(config.seed, f"check {k}"))
        ev = score(eps)
        # the fraction of optimal; a world with no optimum: the share reaching the goal
        value = ev["optimality"] if ev["optimality"] is not None else ev["success"]
        entry = {"attempt": k, "seed": self._seed(k),
                 "episodes": self.attempt_done, "check_episodes": ev["episodes"],
                 "optimality": ev["optimality"], "success": ev["success"]}
        self.attempts.append(entry)
        perfect = value >= 1.0
        # the check vouches for a policy optimal in every episode, and ranks no others (in
        # gripper a better check of an imperfect policy acted worse at 50 balls): the first
        # attempt is kept until one is optimal in its check
        if self.kept_attempt is None or perfect:
            kept = write_atomic(self.saved.with_name(f"attempt-{k}.pl"),
                                self.saved.read_text(encoding="utf-8"))
            self.kept_attempt = (k, kept)
            self._publish(kept)
            self.policy_episodes = self.attempt_done
        if report is not None:
            report({"kind": "check", "entry": {**entry, "perfect": perfect,
                                               "restart": not perfect and k < config.restarts}})
        return perfect

    def learn(self, report: Callable[[dict[str, Any]], None] | None,
              policy_in: str | Path | None, traces: int, monitor: Any) -> dict[str, Any]:
        """The run itself (see :func:`learn_task`): its result when it finishes."""
        config, world = self.config, self.world
        task = world.task(config.task)
        learner = world.learner(config.learner, **config.params)
        world.attach(learner, config.seed, task)
        if policy_in is not None:
            world.load_policy(policy_in)
        curve = self.curve

        def evaluate() -> None:
            self._keep_policy()
            self._go_on()
            eps = world.episodes(task, config.train_sizes, config.eval_episodes, "greedy",
                                 optimal=True, trace=monitor is not None,
                                 seed=evaluation_seed(config.seed, f"point {len(curve)}"))
            ev = score(eps)
            positions, details = world.size()
            self.memory = {**details, "positions": positions}
            entry = {"point": len(curve), **ev, "eval_episodes": ev["episodes"],
                     "episodes": self.done, "learning_steps": self.learn_steps,
                     "memory_positions": positions}
            if self.attempt:
                entry["attempt"] = self.attempt
            curve.append(entry)
            if report is not None:
                report({"kind": "point", "entry": entry})
            if monitor is not None:
                _monitor_point(monitor, world, config, entry, eps)

        if monitor is not None:
            monitor.status("initial evaluation", f"{config.learner} on {config.task}: "
                           f"{config.eval_episodes} greedy episodes")
        evaluate()
        # restarts start from nothing: a run that goes on from a saved policy has none
        restarts = config.restarts if policy_in is None and config.episodes > 0 else 0
        while True:
            while self.attempt_done < config.episodes:
                if monitor is not None:
                    done = self.attempt_done
                    upto = min(done + config.block, config.episodes)
                    again = f" (restart {self.attempt})" if self.attempt else ""
                    monitor.status("learning", f"{config.learner} learns {config.task}{again}: "
                                   f"episodes {done + 1}-{upto} of {config.episodes}",
                                   done=done, total=config.episodes)
                n = min(config.block, config.episodes - self.attempt_done)
                self._go_on()
                t0 = time.perf_counter()
                eps = world.episodes(task, config.train_sizes, n, "learn",
                                     updates=config.updates)
                self.learn_seconds += time.perf_counter() - t0
                self.learn_steps += sum(e.steps for e in eps)
                self.done += n
                self.attempt_done += n
                evaluate()
            if not restarts or self._check(task, report) or self.attempt == restarts:
                break
            self.attempt, self.attempt_done = self.attempt + 1, 0
            world.attach(world.learner(config.learner, **config.params),
                         self._seed(self.attempt), task)
        if self.kept_attempt is not None and self.kept_attempt[0] != self.attempt:
            kept = self.kept_attempt[1]                 # an earlier attempt: learned again
            world.attach(world.learner(config.learner, **config.params), config.seed, task)
            world.load_policy(kept)
            write_atomic(self.saved, kept.read_text(encoding="utf-8"))
        positions, details = world.size()
        if monitor is not None:
            monitor.status("evaluating", "no further learning: sizes "
                           + ", ".join(map(str, config.test_sizes)))
        for size in config.test_sizes:
            self._go_on()
            # only the episodes kept for replay bring their steps back (an answer of 100
            # traced episodes of 50 blocks is millions of terms); the rest follow from a
            # stream of their own
            kept = min(traces, config.eval_episodes)
            t0 = time.process_time()
            eps = world.episodes(task, [size], kept, "greedy", optimal=True, trace=True,
                                 seed=evaluation_seed(config.seed, f"size {size}")) \
                if kept else []
            timed = eps
            if config.eval_episodes > kept:
                t0 = time.process_time()
                timed = world.episodes(task, [size], config.eval_episodes - kept, "greedy",
                                       optimal=True,
                                       seed=evaluation_seed(config.seed,
                                                            f"size {size} untraced"))
                eps += timed
            self._eval_cost(size, timed, time.process_time() - t0)
            self.test[str(size)] = score(eps)
            if traces:
                self.kept[str(size)] = [{"goal": e.goal, "steps": e.steps,
                                         "optimal": e.optimal, "reached": e.reached,
                                         "trace": list(e.trace)} for e in eps[:traces]]
        timing = self._timing()
        if config.speed:
            sizes = config.cost_sizes or sorted({*config.train_sizes, *config.test_sizes})
            timing["step_cost_by_size"] = step_cost_by_size(
                world, task, self.saved, sizes, seed=config.seed,
                fit_sizes=[s for s in sizes if s >= min(config.test_sizes, default=0)])
            timing["shape"] = _shape(world, task, self.saved, config.train_sizes)
        out = {"world": Path(config.world).name, "task": config.task,
               "learner": config.learner, "seed": config.seed, "curve": curve,
               "test": self.test, "final": self._final(),
               "memory": {**details, "positions": positions}, "timing": timing}
        if self.attempts:
            out["attempts"] = self.attempts
            out["kept_attempt"] = self.kept_attempt[0] if self.kept_attempt else 0
        if traces:
            out["traces"] = self.kept
            out["graph"] = world.engine.graph()
        return out

    def _final(self) -> dict[str, Any] | None:
        """The last evaluation point of the kept policy (with restarts: of the kept
        attempt)."""
        kept = self.kept_attempt[0] if self.kept_attempt is not None else self.attempt
        return next((e for e in reversed(self.curve) if e.get("attempt", 0) == kept),
                    self.curve[-1] if self.curve else None)

    def _eval_cost(self, size: int, eps: Sequence[Any], seconds: float) -> None:
        """Keep what the greedy episodes of one test size cost: CPU milliseconds per
        episode and microseconds per step (the untraced episodes when there are some: a
        traced episode's steps cross back into Python)."""
        if eps:
            steps = sum(e.steps for e in eps)
            self.eval_cost[str(size)] = {
                "episodes": len(eps), "steps": steps,
                "cpu_ms_per_episode": 1e3 * seconds / len(eps),
                "cpu_us_per_step": 1e6 * seconds / steps if steps else None}

    def _timing(self) -> dict[str, Any]:
        out = {"learning_seconds": self.learn_seconds, "learning_steps": self.learn_steps,
               "learning_steps_per_second": self.learn_steps / self.learn_seconds
               if self.learn_seconds else None}
        if self.eval_cost:
            out["greedy_episode_cost_by_size"] = {"clock": "process CPU time",
                                                  "sizes": dict(self.eval_cost)}
        return out

    def partial(self, exc: BaseException) -> dict[str, Any]:
        """What the run has done, for a stop or an error (no call into Prolog: the crossing
        that was running may have been cut)."""
        config = self.config
        out = {"world": Path(config.world).name, "task": config.task,
               "learner": config.learner, "seed": config.seed, "curve": self.curve,
               "test": self.test, "final": self._final(),
               "memory": self.memory, "timing": self._timing(), "partial": True,
               "stopped_by": "error" if not isinstance(exc, KeyboardInterrupt)
               else "signal", "episodes_learned": self.done,
               "policy_episodes": self.policy_episodes}
        if self.attempts:
            out["attempts"] = self.attempts
        if not isinstance(exc, KeyboardInterrupt):
            out["error"] = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if self.kept:
            out["traces"] = self.kept
        return out


def evaluation_seed(seed: int, point: str) -> int:
    """The seed of an evaluation's own random stream: a hash of the run's ``seed`` and the
    evaluation ``point`` (``point 3``, ``size 50``), so every evaluation draws the same
    start states whatever was learned or evaluated before it, and none draws from the
    learner's stream (as Gymnasium's seeded ``reset``)."""
    return _stream_seed(f"relrl evaluation {seed} {point}")


def _stream_seed(text: str) -> int:
    """A seed from a hash of ``text`` (48 bits)."""
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:6], "big")


def restart_seed(seed: int, attempt: int) -> int:
    """The learner's seed for restart ``attempt`` (1, 2, ...) of a run seeded ``seed``: a
    stream of its own, the same in every run of that seed."""
    return _stream_seed(f"relrl restart {seed} {attempt}")


def _monitor_point(hub: Any, world: World, config: LearnConfig, entry: dict[str, Any],
                   eps: Sequence[Any]) -> None:
    """Give the live monitor one evaluation: a point of its plot (the fraction of optimal at
    the number of learning episodes), the learned tree, and the last state of the first
    greedy episode (as the replay shows it)."""
    from relrl.worlds.replay import step_rows

    hub.tick(entry["episodes"], [entry["optimality"]], entry["success"])
    hub.set_tree(world.engine.graph())
    if eps:
        ep = eps[0]
        rows = step_rows({"goal": ep.goal, "steps": ep.steps, "optimal": ep.optimal,
                          "trace": ep.trace}, world=Path(config.world).name, size=ep.size,
                         label=f"greedy after {entry['episodes']} episodes "
                               + (f"(of optimal {entry['optimality']:.3f})"
                                  if entry["optimality"] is not None else "(no optimum)"),
                         t0=entry["episodes"])
        if rows:
            hub.publish(rows[-1])


def step_cost_by_size(world: World, task: Any, policy: Path, sizes: Sequence[int], *,
                      episodes: int = 20, rounds: int = 5, fit_sizes: Sequence[int] = (),
                      seed: int = 0) -> dict[str, Any]:
    """CPU microseconds per learning step at each size, from the same saved policy.

    For each of ``rounds`` rounds, each size in turn: load ``policy`` (not timed), learn
    ``episodes`` episodes at that size in one crossing, drawn from a stream of the round's
    own (seeded from ``seed`` and the round: a run measures the same episodes again, so
    its figures differ only by the machine's noise), timed by the CPU time of the
    process (``time.process_time``: Prolog runs in it, and other work on a shared machine
    does not count). Sizes alternate within a round, so what changes from round to round
    touches every size alike. Returns per size the median over rounds of microseconds per
    step and the steps each round learned; the ratio of each size's cost to the smallest
    size's beside the ratio of the sizes (linear growth: the two equal); and ``slope``, the
    exponent k of cost ∝ size^k fitted on logarithms over all the sizes (linear growth:
    k = 1); with ``fit_sizes`` (two or more of ``sizes``: the test sizes, 10-50 blocks)
    also ``fit_slope``, k over those sizes alone, where a cost that grows faster than the
    world shows (a fixed cost per step weighs on the small sizes and flattens ``slope``).
    """
    from relrl.experiments.results import loglog_slope

    per: dict[int, list[float]] = {s: [] for s in sizes}
    work: dict[int, list[int]] = {s: [] for s in sizes}
    for r in range(rounds):
        for size in sizes:
            world.load_policy(policy)
            t0 = time.process_time()
            eps = world.episodes(task, [size], episodes, "learn",
                                 seed=evaluation_seed(seed, f"step cost round {r}"))
            dt = time.process_time() - t0
            steps = sum(e.steps for e in eps)
            work[size].append(steps)
            if steps:
                per[size].append(1e6 * dt / steps)
    world.load_policy(policy)
    med = {s: sorted(v)[len(v) // 2] if v else None for s, v in per.items()}
    base = sizes[0]
    return {"sizes": list(sizes), "clock": "process CPU time", "rounds": rounds,
            "us_per_step": {str(s): med[s] for s in sizes},
            "steps": {str(s): work[s] for s in sizes},
            "cost_ratio": {str(s): (med[s] / med[base]) if med[s] and med[base] else None
                           for s in sizes},
            "size_ratio": {str(s): s / base for s in sizes},
            "slope": loglog_slope(sizes, [med[s] for s in sizes]),
            **({"fit_sizes": list(fit_sizes),
                "fit_slope": loglog_slope(fit_sizes, [med[s] for s in fit_sizes])}
               if len(fit_sizes) >= 2 else {})}


def _shape(world: World, task: Any, policy: Path, sizes: Sequence[int], *,
           episodes: int = 40, rounds: int = 3) -> dict[str, Any]:
    """Greedy episodes one per crossing against all in one crossing (alternating rounds):
    microseconds per step each way and the batch's speed-up."""
    single, batch = [], []
    world.load_policy(policy)
    for _ in range(rounds):
        t0 = time.perf_counter()
        steps = sum(e.steps for _ in range(episodes)
                    for e in world.episodes(task, sizes, 1, "greedy"))
        single.append(1e6 * (time.perf_counter() - t0) / max(1, steps))
        t0 = time.perf_counter()
        steps = sum(e.steps for e in world.episodes(task, sizes, episodes, "greedy"))
        batch.append(1e6 * (time.perf_counter() - t0) / max(1, steps))
    s, b = sorted(single)[rounds // 2], sorted(batch)[rounds // 2]
    return {"us_per_step_one_episode_per_call": s, "us_per_step_batch": b,
            "batch_speedup": s / b if b else None, "episodes_per_batch": episodes}
