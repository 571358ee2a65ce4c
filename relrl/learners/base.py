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
from typing import Any, ClassVar

import numpy as np

from relrl.errors import ConfigError
from relrl.kb import KnowledgeBase
from relrl.terms import Term, Var

__all__ = ["Learner", "StepOut", "register", "make_learner", "LEARNERS", "COMMON_DEFAULTS"]

#: Parameters every learner takes: the reward for a perceived reinforcer and otherwise.
COMMON_DEFAULTS: dict[str, float] = {"reward_positive": 10.0, "reward_negative": -1.0}


@dataclass
class StepOut:
    """What the engine's control step reports."""

    code: int                      #: state code (sum of 2^x)
    necessity: str                 #: active necessity, or "none"
    outputs: dict[str, float]      #: every necessity unit's output y
    reward: float                  #: reward for the previous response
    allowed: list[Term]            #: responses allowed now
    action: Term                   #: the learner's choice ("none" when nothing is allowed)
    allowed_index: list[int] = field(default_factory=list)  #: their indices (declaration order)
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

    Subclasses set ``name``, ``engine`` (the Prolog side: ``etg``, ``contingency`` or
    ``external``) and ``defaults``; Python-side learners override :meth:`act`.
    """

    name: ClassVar[str]
    engine: ClassVar[str]
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
        self.kb: KnowledgeBase | None = None
        self.rng = np.random.default_rng(0)

    def _check_params(self) -> None:
        """Validate parameter ranges (override to add checks)."""
        for key in ("alpha", "gamma", "epsilon"):
            if key in self.params and not 0.0 <= self.params[key] <= 1.0:
                raise ConfigError(f"{key} must be in [0, 1], not {self.params[key]}")

    def attach(self, kb: KnowledgeBase, seed: int | None) -> None:
        """Start learning in ``kb``: configure the engine, seed the random numbers."""
        self.kb = kb
        self.rng = np.random.default_rng(seed)
        params = [("=", k, v) for k, v in self.params.items()]
        kb.call("relrl_engine:engine_configure", kb.module, self.engine, params,
                seed if seed is not None else "none")
        self.responses: list[Term] = kb.declarations("response")

    def act(self, out: StepOut, learning: bool, explore: bool | None = None) -> Term:
        """Return the response to emit. Prolog learners have already chosen."""
        return out.action

    def end_episode(self) -> None:  # noqa: B027 - an optional hook
        """Called when an interaction ends (the engine forgets the last step)."""

    @abc.abstractmethod
    def size(self) -> dict[str, int]:
        """The learner's memory, with ``positions`` in the paper's sense."""

    def _engine_size(self) -> Term:
        """The engine's report of a Prolog learner's memory (relrl_engine:engine_size/2)."""
        assert self.kb is not None
        (size,) = self.kb.call("relrl_engine:engine_size", self.kb.module, Var())
        return size

    def explain(self, *, now: bool = False) -> dict[str, Any]:
        """Why the learner chooses what it chooses in the last step's state (or, with
        ``now``, in the state working memory holds now)."""
        assert self.kb is not None
        pred = "relrl_engine:engine_explain_now" if now else "relrl_engine:engine_explain"
        (exp,) = self.kb.call(pred, self.kb.module, Var())
        return self._explain_from(exp)

    def tree(self) -> str:
        """The learner's tree drawn as text ("" for learners without a tree)."""
        assert self.kb is not None
        (text,) = self.kb.call("relrl_engine:engine_tree", self.kb.module, Var())
        return text

    @abc.abstractmethod
    def _explain_from(self, exp: Term) -> dict[str, Any]:
        """Turn the engine's explanation term into a dict (see :meth:`explain`)."""

    def save(self, path: str | Path, header: str = "") -> Path:
        """Save the learned knowledge (atomic write); returns the file written."""
        assert self.kb is not None
        path = Path(path)
        self.kb.call("relrl_engine:engine_save", self.kb.module, str(path),
                     header or f"relrl policy: {self.name} learner")
        return path

    def load(self, path: str | Path) -> None:
        """Load knowledge saved by :meth:`save` into the attached knowledge base."""
        assert self.kb is not None
        self.kb.load(path)
        self.kb.call("relrl_engine:engine_adopt", self.kb.module)
