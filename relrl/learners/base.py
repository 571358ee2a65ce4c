"""The learner interface and what a learner is made from: its declared parameters.

A learner is chosen by name (``make_learner("etg", alpha=0.2)``, :mod:`relrl.learners.registry`).
Learners that keep their knowledge in Prolog (ETG, contingency, tg) choose and learn inside
the engine's control step, so a step costs one gateway call; a learner that keeps numbers in
Python (Q-learning) gets the state, necessity, reward and allowed responses from that same
call and chooses itself.
"""

from __future__ import annotations

import abc
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from relrl.errors import ConfigError
from relrl.reward import PAPER_REWARD
from relrl.terms import Term

if TYPE_CHECKING:
    from relrl.engine import Engine
    from relrl.kb import KnowledgeBase

__all__ = ["COMMON", "COMMON_DEFAULTS", "DOMAINS", "FAMILIES", "Learner", "LearnerSpec",
           "Parameter", "StepOut", "WORLDS"]

#: The families of tasks a learner may serve: the domains of the simulator and the robot,
#: and worlds written in Prolog (docs/worlds.md).
DOMAINS = "domains"
WORLDS = "worlds"
FAMILIES = (DOMAINS, WORLDS)

#: The kinds of parameter values (``relrl_engine:learner_parameter/4``): what each allows
#: (``whole``: a whole number >= the parameter's ``least``), and that as text.
_KINDS = {"unit": (lambda v: 0.0 <= v <= 1.0, "in [0, 1]"),
          "open_unit": (lambda v: 0.0 < v < 1.0, "in (0, 1)"),
          "nonneg": (lambda v: v >= 0, ">= 0"),
          "whole": (lambda v: v == int(v), "a whole number"),
          "flag": (lambda v: v in (0.0, 1.0), "0 or 1"),
          "number": (lambda v: True, "a number")}


@dataclass(frozen=True)
class Parameter:
    """A learner's parameter: its name, default and the values it takes (its kind:
    ``unit``, ``open_unit``, ``nonneg``, ``whole`` (>= ``least``), ``flag`` or ``number``)."""

    name: str
    default: float
    kind: str = "number"
    least: int = 0

    def __post_init__(self) -> None:
        if self.kind not in _KINDS:
            raise ValueError(f"parameter {self.name}: unknown kind {self.kind!r}")

    def holds(self, value: float) -> bool:
        """Whether ``value`` (a finite number) is a value of this parameter's kind."""
        return _KINDS[self.kind][0](value) and (self.kind != "whole" or value >= self.least)

    @property
    def allowed(self) -> str:
        """The values of this parameter's kind, as text (``in [0, 1]``, ...)."""
        return _KINDS[self.kind][1] + (f" >= {self.least}" if self.kind == "whole" else "")

    def value(self, learner: str, value: object) -> float:
        """``value`` as this parameter of ``learner`` takes it (a float).

        Raises:
            ConfigError: not a finite number of the parameter's kind.
        """
        try:
            number = float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            raise ConfigError(f"parameter {self.name} of learner {learner!r} must be a "
                              f"number, not {value!r}") from None
        if not math.isfinite(number):
            raise ConfigError(f"parameter {self.name} of learner {learner!r} must be a "
                              f"finite number, not {value!r}")
        if not self.holds(number):
            raise ConfigError(f"{self.name} must be {self.allowed}, not {number} (learner "
                              f"{learner!r})")
        return number


#: Parameters every learner takes, read by the engine: the reward for a perceived reinforcer
#: and otherwise (the task's reward, :data:`relrl.reward.PAPER_REWARD`).
COMMON = (Parameter("reward_positive", PAPER_REWARD.attention),
          Parameter("reward_negative", PAPER_REWARD.other))
COMMON_DEFAULTS: dict[str, float] = {p.name: p.default for p in COMMON}


@dataclass(frozen=True)
class LearnerSpec:
    """What a learner is chosen by: its name, the Prolog learner behind it (``external``
    for one that chooses in Python), its own parameters in declaration order, and the
    families of tasks it serves, each with its defaults there where they differ."""

    name: str
    engine: str
    parameters: tuple[Parameter, ...]
    serves: Mapping[str, Mapping[str, float]]

    def defaults(self, family: str) -> dict[str, float]:
        """Every parameter's default in ``family``, the common ones first."""
        return {**COMMON_DEFAULTS, **{p.name: p.default for p in self.parameters},
                **self.serves.get(family, {})}


@dataclass
class StepOut:
    """What a control step reports (:meth:`relrl.loop.Agent.step`)."""

    code: int                      #: state code (sum of 2^x)
    necessity: str                 #: active necessity, or "none"
    outputs: dict[str, float]      #: every necessity unit's output y
    reward: float                  #: reward for the previous response
    allowed: list[Term]            #: responses allowed now
    action: Term | None            #: the learner's choice (None when nothing is allowed)
    allowed_index: list[int] = field(default_factory=list)  #: their indices (declaration order)
    reinforced: bool = False       #: a reinforcer was perceived this step
    memory: tuple[tuple[int, Term], ...] | None = None   #: (age, element), when asked
    memory_size: int | None = None                        #: when asked
    explanation: dict[str, Any] | None = None             #: as Learner.explain, when asked
    extra: dict[str, Any] = field(default_factory=dict)


class Learner(abc.ABC):
    """Base class of relrl's learners, made from a :class:`LearnerSpec` by the registry
    (:func:`relrl.learners.make_learner`).

    A subclass is the Python side of one learner, registered under its ``name``
    (:func:`relrl.learners.registry.register`): what Python really does for it (reading its
    explanations, choosing in Python). A learner declared in Prolog takes its parameters
    and families from the declarations (``relrl_engine:learner_parameter/4``,
    ``learner_serves/3``); one that chooses in Python (through the engine's ``external``
    learner) declares them as its class's ``python_spec``.

    Args:
        spec: the learner's name, Prolog learner, parameters and families.
        family: the family of tasks it learns (``domains`` or ``worlds``), whose defaults
            it takes.
        **params: parameters over those defaults.

    Raises:
        ConfigError: an unknown parameter, or a value not of its parameter's kind.
    """

    #: the learner a subclass is the Python side of (an instance's: its spec's name)
    name: str = ""
    #: a learner that chooses in Python: its name, parameters and families
    python_spec: ClassVar[LearnerSpec | None] = None

    def __init__(self, spec: LearnerSpec, family: str = DOMAINS, **params: float) -> None:
        self.spec = spec
        self.name = spec.name
        #: the Prolog learner behind this one (``external`` for a learner choosing in Python)
        self.engine_name = spec.engine
        allowed = {p.name: p for p in (*COMMON, *spec.parameters)}
        unknown = sorted(set(params) - set(allowed))
        if unknown:
            raise ConfigError(f"unknown parameter {unknown[0]!r} for learner {self.name!r} "
                              f"(known: {', '.join(sorted(allowed))})")
        self.params: dict[str, float] = {
            key: allowed[key].value(self.name, params.get(key, default))
            for key, default in spec.defaults(family).items()}
        self._check_params()
        self.engine: Engine | None = None
        self.rng = np.random.default_rng(0)

    @property
    def kb(self) -> KnowledgeBase | None:
        """The knowledge base the learner is attached to (None before :meth:`attach`)."""
        return self.engine.kb if self.engine is not None else None

    def _check_params(self) -> None:  # noqa: B027 - an optional hook
        """Check what no one parameter's kind says (a relation between parameters)."""

    def attach(self, engine: Engine, seed: int | None) -> None:
        """Start learning with ``engine``: configure it, seed the random numbers."""
        self.engine = engine
        self.rng = np.random.default_rng(seed)
        engine.configure(self.engine_name, self.params, seed)
        self.responses: list[Term] = engine.responses

    def _engine(self) -> Engine:
        if self.engine is None:
            raise ConfigError(f"the {self.name} learner is not attached to an agent yet")
        return self.engine

    def act(self, out: StepOut, learning: bool, explore: bool | None = None) -> Term | None:
        """Return the response to emit. Prolog learners have already chosen."""
        return out.action

    def end_episode(self) -> None:  # noqa: B027 - an optional hook
        """Called when an interaction ends (the engine forgets the last step)."""

    def episode_state(self) -> Any:
        """What an evaluation may disturb on the Python side (random stream, last step);
        :meth:`set_episode_state` puts it back (see :meth:`relrl.loop.Agent.preserved`)."""
        return self.rng.bit_generator.state

    def set_episode_state(self, state: Any) -> None:
        """Put back what :meth:`episode_state` saved."""
        self.rng.bit_generator.state = state

    def size(self) -> dict[str, int]:
        """The learner's memory: ``positions`` in the paper's sense and its own counts."""
        positions, details = self._engine().size()
        return {**details, "positions": positions}

    def explain(self, *, now: bool = False) -> dict[str, Any]:
        """Why the learner chooses what it chooses in the last step's state (or, with
        ``now``, in the state working memory holds now)."""
        return self.decode_explanation(self._engine().explain("now" if now else "last"))

    def decode_explanation(self, exp: Term) -> dict[str, Any]:
        """Turn the engine's ``explanation(Learner, State, Necessity, Detail)`` into a dict
        with ``learner``, ``state``, ``necessity`` and what the learner adds."""
        _, _, state, necessity, detail = exp
        return {"learner": self.name, "state": state, "necessity": necessity,
                **self._explain_from(detail, state, necessity)}

    @abc.abstractmethod
    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """The learner's part of an explanation (``path``, ``ranked``, ...)."""

    def tree(self) -> str:
        """The learner's knowledge drawn as text ("" for learners without a drawing)."""
        return self._engine().text()

    def graph(self) -> dict[str, list[dict[str, Any]]]:
        """The learner's tree as nodes and edges (empty for learners without a tree)."""
        return self._engine().graph()

    def save(self, path: str | Path, header: str = "") -> Path:
        """Save the learned knowledge (atomic write); returns the file written."""
        return self._engine().save(path, header or f"relrl policy: {self.name} learner")

    def load(self, path: str | Path) -> None:
        """Load knowledge saved by :meth:`save`, read as data (never run).

        Raises:
            PolicyError: not this learner's policy for this domain (names file and line).
        """
        self._engine().load_policy(path)
