"""Acting on a saved policy in a world: greedy episodes, no learning, scored against the optimum.

:func:`evaluate_policy` is ``relrl evaluate``: a policy saved by ``relrl learn`` (or ``relrl
experiment worlds``) acts greedily — no exploration, no learning — from start states of a
researcher's own (:func:`read_states`: a Prolog file of terms or a JSON file of facts, both
read as data) or from the world's initial_state/2 at each of a list of sizes. Per episode:
the moves, the optimal number of moves (optimal_steps/3, else a breadth-first search) and
whether the goal was reached; per size (or per states file) the mean fraction of optimal and
the success rate (:func:`relrl.worlds.world.score`). The episodes of a size draw from a
random stream seeded from the seed and the size alone (the same start states for every
policy evaluated with that seed).

Example:
    >>> from relrl.worlds.evaluate import evaluate_policy
    >>> out = evaluate_policy("examples/worlds/blocks.pl", "runs/stack/policy.pl", "stack",
    ...                       sizes=[10, 20], episodes=20)
    >>> out["summary"]["20"]["optimality"]
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from relrl.bridge.calls import display_path
from relrl.engine import one
from relrl.errors import ConfigError
from relrl.terms import Term, Var, format_term
from relrl.worlds.learn import evaluation_seed
from relrl.worlds.world import World, score

__all__ = ["Start", "evaluate_policy", "read_states"]

#: the states file's size limit (bytes): a states file is hand-made or generated, not bulk data
MAX_STATES_BYTES = 64 * 1024 * 1024


@dataclass(frozen=True)
class Start:
    """A start state given in a states file."""

    facts: list[Term]            #: the state's facts
    task: Term | None            #: the episode's task (an instance of the evaluated task)
    where: str                   #: ``file:line`` (Prolog) or ``file: state N`` (JSON)


def read_states(world: World, path: str | Path, task: Term) -> list[Start]:
    """The start states of ``path``: a Prolog file (one term per state: a list of facts,
    ``state(Facts)`` or ``state(Facts, Task)``) or, for a ``.json`` file, a list whose items
    are lists of facts as text or ``{"state": [...], "task": "on(b1, b2)"}``. Read as data,
    never run.

    Raises:
        ConfigError: the file is missing, too large or not a states file of the world: one
            line naming the file and the line (Prolog) or the state's number (JSON).
    """
    path = Path(path)
    shown = display_path(str(path))
    if not path.is_file():
        raise ConfigError(f"--states {shown}: no such file")
    if path.stat().st_size > MAX_STATES_BYTES:
        raise ConfigError(f"--states {shown}: larger than {MAX_STATES_BYTES >> 20} MiB")
    if path.suffix.lower() == ".json":
        return _json_states(world, path, shown, task)
    answer = one(world.kb, "world_read_states", world.kb.module, str(path.resolve()), task)
    if answer[0] == "problem":
        raise ConfigError(f"{shown}:{answer[1]}: {answer[2]}")
    return [Start(facts=list(facts), task=None if inst == "none" else inst,
                  where=f"{shown}:{line}")
            for _, line, facts, inst in answer[1]]


def _json_states(world: World, path: Path, shown: str, task: Term) -> list[Start]:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{shown}: not UTF-8 text ({exc.reason})") from None
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{shown}:{exc.lineno}: not JSON: {exc.msg}") from None
    if not isinstance(data, list) or not data:
        raise ConfigError(f"{shown}: a JSON states file is a non-empty list of states (each "
                          f"a list of facts as text, or {{\"state\": [...], \"task\": ...}})")
    starts = []
    for i, item in enumerate(data, 1):
        where = f"{shown}: state {i}"
        inst: Term | None = None
        if isinstance(item, dict):
            extra = set(item) - {"state", "task"}
            if "state" not in item or extra:
                raise ConfigError(f"{where}: an object needs \"state\" (and may give \"task\")"
                                  f", not {sorted(item)}")
            if "task" in item:
                inst = _instance(world, item["task"], task, where)
            item = item["state"]
        if not isinstance(item, list) or not all(isinstance(f, str) for f in item):
            raise ConfigError(f"{where}: a state is a list of facts as text, e.g. "
                              f"[\"on(b1, floor)\", \"clear(b1)\"]")
        answer = one(world.kb, "world_state_texts", world.kb.module, list(item), task)
        if answer[0] == "problem":
            fact = f", fact {answer[1]}" if answer[1] else ""
            raise ConfigError(f"{where}{fact}: {answer[2]}")
        starts.append(Start(facts=list(answer[1]), task=inst, where=where))
    return starts


def _instance(world: World, text: Any, task: Term, where: str) -> Term:
    if not isinstance(text, str):
        raise ConfigError(f"{where}: \"task\" must be text, e.g. \"on(b1, b2)\"")
    try:
        inst = world.task(text)
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from None
    if not _subsumes(task, inst) or _has_var(inst):
        raise ConfigError(f"{where}: task {text!r} is not an instance of the evaluated task "
                          f"{format_term(task)}")
    return inst


def _subsumes(general: Term, specific: Term) -> bool:
    if isinstance(general, Var):
        return True
    if isinstance(general, tuple):
        return (isinstance(specific, tuple) and len(general) == len(specific)
                and general[0] == specific[0]
                and all(_subsumes(g, s) for g, s in zip(general[1:], specific[1:], strict=True)))
    return general == specific


def _has_var(term: Term) -> bool:
    if isinstance(term, Var):
        return True
    return isinstance(term, tuple) and any(_has_var(a) for a in term[1:])


def _check_optima(eps: Sequence[Any], starts: list[Start] | None, label: str) -> None:
    """Refuse an episode that reached its goal in fewer moves than its optimum: the optimum
    (the world's optimal_steps/3) is then wrong for that state, most often a given state that
    breaks the world's invariants (a block on two blocks), and every figure would be too."""
    for i, e in enumerate(eps):
        if e.reached and e.optimal is not None and e.steps < e.optimal:
            where = starts[i].where if starts is not None else f"size {label}, episode {i + 1}"
            raise ConfigError(f"{where}: the goal {e.goal} was reached in {e.steps} moves, "
                              f"fewer than the optimum the world gives ({e.optimal}): not a "
                              f"state the world's optimal_steps/3 describes (does it break "
                              f"the world's invariants, e.g. a block on two blocks?)")


def evaluate_policy(world_path: str | Path, policy: str | Path, task_text: str, *,
                    sizes: Sequence[int] = (), episodes: int = 100,
                    states: str | Path | None = None, seed: int = 0,
                    actions: bool = False) -> dict[str, Any]:
    """Act greedily on ``policy`` in the world at ``world_path`` and score each episode.

    Args:
        world_path: the world file.
        policy: a policy saved by ``relrl learn`` (read as data).
        task_text: the task (its name or an instance).
        sizes: with no ``states``: ``episodes`` episodes at each of these sizes, start
            states from the world's initial_state/2.
        episodes: episodes per size.
        states: a states file (:func:`read_states`): one episode from each state.
        seed: the random seed (start states, a task's drawn goal, ties).
        actions: keep each episode's actions.

    Returns:
        A JSON-ready dict: ``rows`` (one per episode: size or state, goal, steps, optimal,
        reached, of_optimal), ``summary`` (per size, or ``states``: :func:`score` and CPU
        seconds per episode), the policy's learner and the configuration.

    Raises:
        ConfigError, PolicyError: a bad task, states file or policy (one line).
    """
    from relrl.engine import policy_learner

    with World(world_path) as world:
        task = world.task(task_text)
        learner = policy_learner(world.kb, Path(policy))
        world.attach(world.learner(learner), seed, task)
        world.load_policy(policy)
        batches: list[tuple[str, list[Start] | None, int | None]]
        if states is not None:
            starts = read_states(world, states, task)
            batches = [("states", starts, None)]
        else:
            world.check_instance(task_text, sizes)  # on(b1, b1), on(b1, b99): one line
            batches = [(str(size), None, size) for size in sizes]
        rows: list[dict[str, Any]] = []
        summary: dict[str, Any] = {}
        for label, starts, size in batches:
            t0 = time.process_time()
            if starts is not None:
                eps = world.episodes_from(task, [(s.facts, s.task) for s in starts],
                                          optimal=True, actions=actions,
                                          seed=evaluation_seed(seed, "states"))
            else:
                eps = world.episodes(task, [size], episodes, "greedy", optimal=True,
                                     actions=actions,
                                     seed=evaluation_seed(seed, f"size {size}"))
            cpu = time.process_time() - t0
            _check_optima(eps, starts, label)
            summary[label] = {**score(eps), "cpu_seconds_per_episode": cpu / max(1, len(eps))}
            for i, e in enumerate(eps):
                row = {"size": e.size, "state": i + 1 if starts is not None else None,
                       "where": starts[i].where if starts is not None else None,
                       "goal": e.goal, "steps": e.steps, "optimal": e.optimal,
                       "reached": e.reached, "of_optimal": e.optimality}
                if actions:
                    row["actions"] = [s["action"] for s in e.trace if s["action"] is not None]
                rows.append(row)
    return {"command": "evaluate", "world": Path(world_path).name, "policy": str(policy),
            "learner": learner, "task": task_text, "seed": seed,
            "sizes": list(sizes) if states is None else None,
            "episodes": episodes if states is None else None,
            "states": str(states) if states is not None else None,
            "summary": summary, "rows": rows}
