"""A world written in Prolog, loaded into a knowledge base, and the episodes run in it.

Example:
    >>> from relrl.worlds import World, make_world_learner, score
    >>> with World("examples/worlds/blocks.pl") as world:
    ...     world.attach(make_world_learner("tg"), seed=0)
    ...     learned = world.episodes("stack", [3, 4, 5], 200, "learn")
    ...     test = world.episodes("stack", [6, 8, 10], 50, "greedy", optimal=True)
    ...     print(score(test)["optimality"])
    1.0
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from relrl.bridge.calls import display_path as _display_path
from relrl.engine import Engine, call, call_semidet, one
from relrl.errors import ConfigError, PrologError
from relrl.kb import KnowledgeBase
from relrl.learners import Learner, make_world_learner
from relrl.terms import Term, Var, format_term

__all__ = ["Episode", "World", "score"]


#: Breadth-first search bound (states) for the optimal number of steps of a world that
#: does not state it (optimal_steps/3).
BFS_LIMIT = 20_000


@dataclass(frozen=True)
class Episode:
    """One episode of a world (``relrl_world:world_episodes/3``)."""

    size: int                  #: the number of objects
    goal: str                  #: the episode's goal, as Prolog text
    steps: int                 #: actions taken
    reward: float              #: the sum of rewards
    reached: bool              #: the goal held at the end
    optimal: int | None        #: the least number of actions to the goal (when asked)
    trace: tuple[dict[str, Any], ...] = ()   #: each step's state and action (when asked)

    @property
    def optimality(self) -> float | None:
        """optimal / steps when the goal was reached, 0 when not (None: optimal unknown)."""
        if self.optimal is None:
            return None
        if not self.reached:
            return 0.0
        return 1.0 if self.steps == 0 else self.optimal / self.steps


def score(episodes: Sequence[Episode]) -> dict[str, Any]:
    """Success rate, mean optimality (optimal / steps, 0 for a failure: RRL's "of optimal
    steps"), the share of episodes solved in exactly the optimal number of steps, mean steps
    and mean optimal steps, over ``episodes``."""
    n = len(episodes)
    if not n:
        return {"episodes": 0, "success": None, "optimality": None, "exactly_optimal": None,
                "steps": None, "optimal_steps": None}
    opt = [e.optimality for e in episodes]
    known = [o for o in opt if o is not None]
    return {"episodes": n,
            "success": sum(e.reached for e in episodes) / n,
            "optimality": sum(known) / len(known) if known else None,
            "exactly_optimal": (sum(1 for e in episodes if e.reached and e.optimal is not None
                                    and e.steps == e.optimal) / len(known)) if known else None,
            "steps": sum(e.steps for e in episodes) / n,
            "optimal_steps": (sum(e.optimal for e in episodes if e.optimal is not None)
                              / len(known)) if known else None}


class World:
    """A world file loaded into a knowledge base of its own.

    Args:
        path: the world file (Prolog; docs/worlds.md).
        timeout: seconds one call (a batch of episodes) may run.

    Raises:
        PrologLoadError: the file is missing or does not load (file:line).
    """

    def __init__(self, path: str | os.PathLike, *, timeout: float = 600.0) -> None:
        self.path = Path(path)
        self.kb = KnowledgeBase(timeout=timeout)
        try:
            self.kb.load(self.path)
            info = {item[0]: item[1:] for item in one(self.kb, "world_info", self.kb.module)}
        except BaseException:
            self.kb.close()
            raise
        self.tasks: list[Term] = list(info["tasks"][0])
        self.actions: list[Term] = list(info["actions"][0])
        self.relations: list[Term] = list(info["relations"][0])
        self.train_sizes: list[int] = list(info["sizes"][0]) or [3]
        self.test_sizes: list[int] = list(info["sizes"][1])
        self.optimal_known: bool = info["optimal"][0] == "true"
        #: the task's discount (discount/1), the learners' gamma unless given; None: theirs
        self.discount: float | None = (None if info["discount"][0] == "none"
                                       else float(info["discount"][0]))
        self.engine = Engine(self.kb)
        self.learner_name: str | None = None

    # -- checking --------------------------------------------------------------------------

    def problems(self) -> list[str]:
        """One ``file:line: problem`` line per problem of the world (prolog/world_check.pl);
        empty when it is valid."""
        lines = []
        for _, path, line, message in one(self.kb, "world_check", self.kb.module):
            where = f"{_display_path(path)}:{line}" if path else _display_path(str(self.path))
            lines.append(f"{where}: {message}")
        return lines

    def task_names(self) -> list[str]:
        """The declared tasks as text (``stack``, ``on(_, _)``)."""
        return [_text(t) for t in self.tasks]

    def task(self, text: str) -> Term:
        """The task ``text`` names: a task's name (``on``) or an instance (``on(b1, b2)``).

        Raises:
            ConfigError: the world declares no such task.
        """
        text = text.strip()
        if re.fullmatch(r"[a-z][A-Za-z0-9_]*", text):
            spec: Term = text
        else:
            try:
                terms = one(self.kb, "parse", self.kb.module, text)
            except PrologError:  # a syntax error in the user's text
                terms = None
            if not terms or len(terms) != 1:
                raise ConfigError(f"--task {text!r}: not a task term (tasks of "
                                  f"{_display_path(str(self.path))}: "
                                  f"{', '.join(self.task_names())})")
            spec = terms[0]
        out = call_semidet(self.kb, "world_task", self.kb.module, spec, Var())
        if out is None:
            raise ConfigError(f"--task {text!r}: no such task in "
                              f"{_display_path(str(self.path))} (tasks: "
                              f"{', '.join(self.task_names())})")
        return out[0]

    def _task(self, task: Term | str) -> Term:
        return self.task(task) if isinstance(task, str) else task

    # -- learning and acting ----------------------------------------------------------------

    def learner(self, name: str, **params: float) -> Learner:
        """The learner ``name`` with its defaults in worlds, the world's discount as its
        gamma (discount/1), and ``params`` over both
        (:func:`~relrl.learners.make_world_learner`)."""
        if self.discount is not None and "gamma" not in params:
            params = {**params, "gamma": self.discount}
        return make_world_learner(name, **params)

    def attach(self, learner: Learner, seed: int, task: Term | str | None = None) -> None:
        """Start ``learner`` (a learner of worlds: :func:`relrl.learners.learners`
        ``("worlds")``) afresh in this world, seeded; for ``task``, a world that declares
        task_rmode/2 modes adds that task's to its bias (or, with task_own_bias/1, uses
        them alone); a world without rmode/1 has the bias generated from its types."""
        if task is not None:
            call(self.kb, "world_for_task", self.kb.module, self._task(task))
        learner.attach(self.engine, seed)
        self.learner_name = learner.name

    def episodes(self, task: Term | str, sizes: Sequence[int], count: int, mode: str = "learn",
                 *, optimal: bool = False, trace: bool = False,
                 updates: str = "episode") -> list[Episode]:
        """Run ``count`` episodes in one crossing into Prolog.

        Args:
            task: a task (:meth:`task`, or its text).
            sizes: each episode's size is drawn from these, uniformly.
            count: the number of episodes.
            mode: ``learn`` (explore and learn), ``explore`` or ``greedy`` (no learning).
            optimal: compute each episode's optimal number of steps (the world's
                optimal_steps/3, else a breadth-first search of at most :data:`BFS_LIMIT`
                states).
            trace: keep each step's state and action.
            updates: ``episode`` (the episode's examples given to the learner when it ends,
                last first: RRL's) or ``online`` (each step's at once).
        """
        if self.learner_name is None:
            raise ConfigError("attach a learner before running episodes")
        options = [("updates", updates), ("optimal", BFS_LIMIT if optimal else 0),
                   ("trace", "true" if trace else "false")]
        spec = ("episodes", self._task(task), [int(s) for s in sizes], int(count), mode,
                options)
        raw = one(self.kb, "world_episodes", self.kb.module, spec)
        return [_episode(e) for e in raw]

    def verify_optimal(self, task: Term | str, size: int, count: int
                       ) -> list[tuple[int | None, int | None]]:
        """``(declared, searched)`` optimal steps for ``count`` random start states: the
        world's optimal_steps/3 against a breadth-first search of its own dynamics."""
        pairs = one(self.kb, "world_verify", self.kb.module, self._task(task), int(size),
                    int(count))
        return [(_int(p[1]), _int(p[2])) for p in pairs]

    def size(self) -> tuple[int, dict[str, int]]:
        """The learner's memory: ``(positions, details)``."""
        return self.engine.size()

    def save_policy(self, path: str | Path, header: str) -> Path:
        """Write the learned policy (readable Prolog, atomic)."""
        return self.engine.save(path, header)

    def load_policy(self, path: str | Path) -> None:
        """Replace the learned knowledge by a saved policy, read as data (a policy learned
        in a world of another size loads: tg's is tied to the relations and bias only)."""
        self.engine.load_policy(path)

    def text(self) -> str:
        """The learner's knowledge as text (tg: its tree)."""
        return self.engine.text()

    # -- life -------------------------------------------------------------------------------

    def close(self) -> None:
        """Drop the knowledge base (may be called twice)."""
        self.kb.close()

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _int(x: Term) -> int | None:
    return x if isinstance(x, int) else None


def _text(term: Term) -> str:
    if isinstance(term, Var):
        return "_"
    if isinstance(term, tuple):
        return f"{term[0]}({', '.join(_text(a) for a in term[1:])})"
    return format_term(term)


def _episode(raw: Term) -> Episode:
    _, size, goal, steps, reward, reached, optimal, trace = raw
    steps_out = []
    for item in trace:
        if item[0] == "step":
            steps_out.append({"state": [format_term(f) for f in item[1]],
                              "action": format_term(item[2]), "reward": item[3]})
        else:
            steps_out.append({"state": [format_term(f) for f in item[1]], "action": None,
                              "reward": None})
    return Episode(size=size, goal=format_term(goal), steps=steps, reward=float(reward),
                   reached=reached == "true", optimal=_int(optimal), trace=tuple(steps_out))

