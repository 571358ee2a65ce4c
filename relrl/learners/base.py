"""The learner interface and the learner registry.

A learner is chosen by name (``make_learner("etg", alpha=0.2)``). Learners that keep their
knowledge in Prolog (ETG, contingency) choose and learn inside the engine's control step, so
a step costs one gateway call; a learner that keeps numbers in Python (Q-learning) gets the
state, necessity, reward and allowed responses from that same call and chooses itself.
"""

from __future__ import annotations

import abc
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from relrl.errors import ConfigError
from relrl.reward import PAPER_REWARD
from relrl.terms import Term

if TYPE_CHECKING:
    from relrl.engine import Engine

__all__ = ["Learner", "StepOut", "register", "make_learner", "LEARNERS", "COMMON_DEFAULTS"]

#: Parameters every learner takes: the reward for a perceived reinforcer and otherwise (the
#: task's reward, :data:`relrl.reward.PAPER_REWARD`).
COMMON_DEFAULTS: dict[str, float] = {"reward_positive": PAPER_REWARD.attention,
                                     "reward_negative": PAPER_REWARD.other}


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


LEARNERS: dict[str, type[Learner]] = {}


def register(cls: type[Learner]) -> type[Learner]:
    """Class decorator: make a learner available by its ``name``."""
    LEARNERS[cls.name] = cls
    return cls


def make_learner(name: str, **params: float) -> Learner:
    """Build the learner registered as ``name`` with ``params``.

    Raises:
        ConfigError: unknown learner name or parameter.
    """
    try:
        cls = LEARNERS[name]
    except KeyError:
        known = ", ".join(sorted(LEARNERS))
        raise ConfigError(f"unknown learner {name!r} (known: {known})") from None
    return cls(**params)


class Learner(abc.ABC):
    """Base class of relrl's learners.

    Subclasses set ``name``, ``engine_name`` (the Prolog learner behind it: ``etg``,
    ``contingency``, or ``external`` for a learner that chooses in Python) and
    ``defaults``; Python-side learners override :meth:`act`.
    """

    name: ClassVar[str]
    engine_name: ClassVar[str]
    defaults: ClassVar[dict[str, float]]

    def __init__(self, **params: float) -> None:
        allowed = {**COMMON_DEFAULTS, **self.defaults}
        unknown = sorted(set(params) - set(allowed))
        if unknown:
            raise ConfigError(f"unknown parameter {unknown[0]!r} for learner {self.name!r} "
                              f"(known: {', '.join(sorted(allowed))})")
        self.params: dict[str, float] = {}
        for key, default in allowed.items():
            value = params.get(key, default)
            try:
                self.params[key] = float(value)
            except (TypeError, ValueError):
                raise ConfigError(f"parameter {key} of learner {self.name!r} must be a number, "
                                  f"not {value!r}") from None
            if not math.isfinite(self.params[key]):
                raise ConfigError(f"parameter {key} of learner {self.name!r} must be a finite "
                                  f"number, not {value!r}")
        self._check_params()
        self.engine: Engine | None = None
        self.rng = np.random.default_rng(0)

    @property
    def kb(self) -> Any:
        """The knowledge base the learner is attached to (None before :meth:`attach`)."""
        return self.engine.kb if self.engine is not None else None

    def _check_params(self) -> None:
        """Validate parameter ranges (override to add checks)."""
        for key in ("alpha", "gamma", "epsilon"):
            if key in self.params and not 0.0 <= self.params[key] <= 1.0:
                raise ConfigError(f"{key} must be in [0, 1], not {self.params[key]}")

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
