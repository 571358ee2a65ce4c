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

import logging
import math
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from relrl.bridge.calls import display_path as _display_path
from relrl.engine import Engine, EngineError, call, call_semidet, one
from relrl.errors import ConfigError, PrologError, QueryTimeout
from relrl.kb import KnowledgeBase
from relrl.learners import Learner, make_world_learner
from relrl.terms import Term, Var, format_term

__all__ = ["Episode", "World", "score"]

_log = logging.getLogger(__name__)


#: Breadth-first search bound (states) for the optimal number of steps of a world that
#: does not state it (optimal_steps/3).
BFS_LIMIT = 20_000
#: States a search visits, from each start state, to tell a task instance whose goal cannot
#: be reached (:meth:`World.check_instance`).
REACH_LIMIT = 2_000
#: Seconds a world's rule may run (``--rule-seconds``): a step of the world, or a goal of it
#: between two steps, that runs longer is stopped with an error naming the rule. A batch of
#: episodes, a check or a search runs as long as it makes progress.
RULE_SECONDS = 10.0


@dataclass(frozen=True)
class Episode:
    """One episode of a world (``relrl_world:world_episodes/3``)."""

    size: int | None           #: the number of objects (None: a given start state)
    goal: str                  #: the episode's goal, as Prolog text
    steps: int                 #: actions taken
    reward: float              #: the sum of rewards
    reached: bool              #: the goal held at the end
    optimal: int | None        #: the least number of actions to the goal (when asked)
    trace: tuple[dict[str, Any], ...] = ()   #: each step's state and action (when asked)
    unreachable: bool = False  #: a search proved the goal unreachable (optimal is None)

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
    and mean optimal steps, over ``episodes``. An episode whose optimum is unknown (a search
    stopped by its limit) or that has none (``unreachable``: a search proved its goal
    unreachable) counts in the success rate, not in the optimality; ``unreachable`` counts
    the latter."""
    n = len(episodes)
    if not n:
        return {"episodes": 0, "success": None, "optimality": None, "exactly_optimal": None,
                "steps": None, "optimal_steps": None, "unreachable": 0}
    opt = [e.optimality for e in episodes]
    known = [o for o in opt if o is not None]
    return {"episodes": n,
            "success": sum(e.reached for e in episodes) / n,
            "optimality": sum(known) / len(known) if known else None,
            "exactly_optimal": (sum(1 for e in episodes if e.reached and e.optimal is not None
                                    and e.steps == e.optimal) / len(known)) if known else None,
            "steps": sum(e.steps for e in episodes) / n,
            "optimal_steps": (sum(e.optimal for e in episodes if e.optimal is not None)
                              / len(known)) if known else None,
            "unreachable": sum(e.unreachable for e in episodes)}


class World:
    """A world file loaded into a knowledge base of its own.

    Every call that runs the world's rules (its check, episodes, searches) stops at Ctrl-C
    (and SIGTERM or SIGHUP, when the command handles them) within a tenth of a second, and
    stops a rule of the world that runs ``rule_seconds`` with a
    :class:`~relrl.errors.QueryTimeout` naming it, however long the whole call runs.

    Args:
        path: the world file (Prolog; docs/worlds.md).
        timeout: seconds a call that runs none of the world's rules may run (a learner's
            save or load); loading the file has ``rule_seconds``.
        rule_seconds: seconds a rule of the world may run (:data:`RULE_SECONDS`).

    Raises:
        PrologLoadError: the file is missing or does not load (file:line).
        ConfigError: ``rule_seconds`` is not a positive number of seconds.
    """

    def __init__(self, path: str | os.PathLike, *, timeout: float = 600.0,
                 rule_seconds: float = RULE_SECONDS) -> None:
        if not (isinstance(rule_seconds, (int, float)) and math.isfinite(rule_seconds)
                and rule_seconds > 0):
            raise ConfigError(f"the rule time limit must be a positive number of seconds, "
                              f"not {rule_seconds!r}")
        self.path = Path(path)
        self.rule_seconds = float(rule_seconds)
        self.kb = KnowledgeBase(timeout=self.rule_seconds)   # the file's directives too
        try:
            self.kb.load(self.path)
            self.kb.timeout = timeout
            info = {item[0]: item[1:] for item in self._ask("world_info", self.kb.module)}
        except BaseException:
            self.kb.close()
            raise
        self.tasks: list[Term] = list(info["tasks"][0])
        self.actions: list[Term] = list(info["actions"][0])
        self.relations: list[Term] = list(info["relations"][0])
        #: the sizes the world declares (sizes/2; [] when it does not)
        self.declared_sizes: dict[str, list[int]] = {"train": list(info["sizes"][0]),
                                                     "test": list(info["sizes"][1])}
        self.train_sizes: list[int] = self.declared_sizes["train"] or [3]
        self.test_sizes: list[int] = self.declared_sizes["test"]
        self.optimal_known: bool = info["optimal"][0] == "true"
        #: the task's discount (discount/1), the learners' gamma unless given; None: theirs
        self.discount: float | None = (None if info["discount"][0] == "none"
                                       else float(info["discount"][0]))
        #: per learner, the parameters the world gives it (learner_param/3)
        self.learner_params: dict[str, dict[str, float]] = {}
        for learner, name, value in info["learner_params"][0]:
            self.learner_params.setdefault(str(learner), {})[str(name)] = float(value)
        self.engine = Engine(self.kb)
        self.learner_name: str | None = None

    # -- checking --------------------------------------------------------------------------

    def problems(self) -> list[str]:
        """One ``file:line: problem`` line per problem of the world (prolog/world_check.pl);
        empty when it is valid."""
        return self.check()[0]

    def check(self) -> tuple[list[str], list[str]]:
        """The world's problems and its warnings (a search stopped by its limit, an action
        template never bound ...), one ``file:line: text`` line each
        (prolog/world_check.pl)."""
        problems: list[str] = []
        warnings: list[str] = []
        for kind, path, line, message in self._ask("world_check", self.kb.module):
            where = (f"{_display_path(path)}:{line}" if path
                     else _display_path(str(self.path)))
            if kind == "warning":
                warnings.append(f"{where}: warning: {message}")
            else:
                problems.append(f"{where}: {message}")
        return problems, warnings

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

    def check_instance(self, text: str, sizes: Sequence[int]) -> None:
        """Refuse a task instance (``on(b1, b2)``; a task's name passes) whose goal cannot be
        reached at one of ``sizes``: an object the world does not have at that size
        (``on(b1, b99)``, ``on(b1, shell(x))``), or a goal no state holds (``on(b1, b1)``),
        found by a breadth-first search of at most :data:`REACH_LIMIT` states. Where a size
        has too many states to search, the objects are still checked, and a goal that no
        smaller size the search can finish reaches is a warning (a goal may need more
        objects than a small world has).

        Raises:
            ConfigError: naming the task and the size.
        """
        text = text.strip()
        if re.fullmatch(r"[a-z][A-Za-z0-9_]*", text):
            return
        task = self.task(text)
        tasks = f"tasks of {_display_path(str(self.path))}: {', '.join(self.task_names())}"
        too_large = []
        for size in sorted(set(sizes)):
            absent = self._ask("world_absent", self.kb.module, task, int(size))
            if absent:
                names = ", ".join(_text(x) for x in absent)  # type: ignore[union-attr]
                raise ConfigError(f"--task {text!r}: its goal cannot be reached: it names "
                                  f"{names}, which no start state of {size} objects holds "
                                  f"({tasks})")
            verdict = self._ask("world_reachable", self.kb.module, task, int(size),
                                REACH_LIMIT)
            if verdict == "unreachable":
                raise ConfigError(f"--task {text!r}: its goal cannot be reached in a world of "
                                  f"{size} objects (a search of every state reachable from "
                                  f"its start states; {tasks})")
            if verdict != "reachable":
                too_large.append(size)
        if too_large and (searched := self._unreached_below(task, min(too_large))):
            _log.warning("--task %r: its goal is reached in no world of %s objects (searched "
                         "whole); %s objects are too many to search, so it is learned as "
                         "asked", text, searched, ", ".join(map(str, too_large)))

    def _unreached_below(self, task: Term, size: int) -> str | None:
        """The sizes below ``size`` that hold the task's objects and whose search finished,
        as ``"2 to 5"``, when none of them reaches the goal; None when one does, or none
        could be searched."""
        searched = []
        for n in range(1, size):
            if self._ask("world_absent", self.kb.module, task, n):
                continue
            verdict = self._ask("world_reachable", self.kb.module, task, n, REACH_LIMIT)
            if verdict == "reachable":
                return None
            if verdict != "unreachable":
                break
            searched.append(n)
        if not searched:
            return None
        return str(searched[0]) if len(searched) == 1 else f"{searched[0]} to {searched[-1]}"

    def _task(self, task: Term | str) -> Term:
        return self.task(task) if isinstance(task, str) else task

    # -- learning and acting ----------------------------------------------------------------

    def learner(self, name: str, **params: float) -> Learner:
        """The learner ``name`` with its defaults in worlds, the world's discount as its
        gamma (discount/1) and the world's values of its parameters (learner_param/3) over
        them, and ``params`` over all (:func:`~relrl.learners.make_world_learner`)."""
        own = dict(self.learner_params.get(name, {}))
        if self.discount is not None:
            own.setdefault("gamma", self.discount)
        return make_world_learner(name, **{**own, **params})

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
                 updates: str = "episode", seed: int | None = None,
                 actions: bool = False) -> list[Episode]:
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
            seed: draw the batch from a random stream of its own seeded with ``seed`` and
                leave the learner's stream as it was (an evaluation that never moves
                learning); None: the learner's stream.
            actions: without ``trace``, keep each step's action alone (its state empty): an
                answer a few bytes a step, whatever the size of the world.
        """
        if self.learner_name is None:
            raise ConfigError("attach a learner before running episodes")
        options = [("updates", updates), ("optimal", BFS_LIMIT if optimal else 0),
                   ("trace", _trace(trace, actions))]
        if seed is not None:
            options.append(("random", int(seed)))
        spec = ("episodes", self._task(task), [int(s) for s in sizes], int(count), mode,
                options)
        raw = self._ask("world_episodes", self.kb.module, spec)
        return [_episode(e) for e in raw]

    def episodes_from(self, task: Term | str, starts: Sequence[tuple[list[Term], Term | None]],
                      mode: str = "greedy", *, optimal: bool = False, trace: bool = False,
                      seed: int | None = None, actions: bool = False) -> list[Episode]:
        """One episode from each start state, in one crossing (:meth:`episodes`' options).

        Args:
            task: a task (:meth:`task`, or its text).
            starts: ``(facts, instance)`` pairs: a start state's facts, and the episode's task
                (an instance of ``task``) or None for ``task`` itself (its goal drawn when
                it leaves one open, task_goal/3).
            mode: ``greedy``, ``explore`` or ``learn``.
            optimal: compute each episode's optimal number of steps.
            trace: keep each step's state and action.
            seed: draw from a stream of the batch's own (see :meth:`episodes`).
            actions: keep each step's action alone (see :meth:`episodes`).

        An episode's ``size`` is None: the state gives it, not a draw.
        """
        if self.learner_name is None:
            raise ConfigError("attach a learner before running episodes")
        options: list[tuple[str, Any]] = [("optimal", BFS_LIMIT if optimal else 0),
                                          ("trace", _trace(trace, actions))]
        if seed is not None:
            options.append(("random", int(seed)))
        spec = ("from", self._task(task),
                [("start", list(facts), "none" if inst is None else inst)
                 for facts, inst in starts], mode, options)
        raw = self._ask("world_episodes_from", self.kb.module, spec)
        return [_episode(e) for e in raw]

    def verify_optimal(self, task: Term | str, size: int, count: int
                       ) -> list[tuple[int | None, int | None]]:
        """``(declared, searched)`` optimal steps for ``count`` random start states: the
        world's optimal_steps/3 against a breadth-first search of its own dynamics."""
        pairs = self._ask("world_verify", self.kb.module, self._task(task), int(size),
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

    # -- calls that run the world's rules ----------------------------------------------------

    def _ask(self, goal: str, *arguments: Term) -> Term:
        """Call ``goal`` (a name of ``python_api/2``) with ``arguments`` and one more output
        argument, under the rule time limit (counted from the world's last step) and
        stopped by Ctrl-C; return the output's value.

        Raises:
            QueryTimeout: a rule of the world ran :attr:`rule_seconds` (named).
            EngineError: the goal failed.
        """
        try:
            with self.kb.interruptible():
                values = self.kb.api_watched(goal, *arguments, seconds=self.rule_seconds)
        except QueryTimeout as exc:
            limit = (f"ran longer than {self.rule_seconds:g} s (a rule that never ends? "
                     "--rule-seconds sets the limit)")
            if exc.rule:
                raise QueryTimeout(f"{exc.where}: rule {exc.rule} {limit}", exc.rule,
                                   exc.where) from None
            raise QueryTimeout(f"{_display_path(str(self.path))}: the world's goal {limit}") \
                from None
        if values is None:
            raise EngineError(f"{goal}/{len(arguments) + 1} failed in {self.kb.module}")
        return values[0]

    # -- life -------------------------------------------------------------------------------

    def close(self) -> None:
        """Drop the knowledge base (may be called twice)."""
        self.kb.close()

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _trace(trace: bool, actions: bool) -> str:
    return "true" if trace else "actions" if actions else "false"


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
    return Episode(size=None if size == "none" else size, goal=format_term(goal),
                   steps=steps, reward=float(reward), reached=reached == "true",
                   optimal=_int(optimal), trace=tuple(steps_out),
                   unreachable=optimal == "unreachable")

