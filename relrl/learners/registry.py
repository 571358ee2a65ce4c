"""The learner registry, asked of relrl's Prolog: the one list of learners.

Every learner of relrl's Prolog declares, beside its hooks, its parameters with their
defaults and kinds and the families of tasks it serves (``relrl_engine:learner_parameter/4``
and ``learner_serves/3``, prolog/learners.pl). The first time Python needs a learner it asks
for them all (``relrl_learners:learner_catalogue/1``, one call) and builds the registry from
the answer: a learner added to Prolog (its file and one line of learners.pl) is chosen by
name from Python with no Python change. Python classes (:func:`register`) add only what
Python does for a learner -- read its explanations, or choose in Python through the engine's
``external`` learner (``qlearning``, whose parameters Python declares) -- and a class for a
learner Prolog does not declare is an error, so the two sides cannot drift apart.

Example:
    >>> from relrl.learners import learners, make_learner, make_world_learner
    >>> learners("domains")
    ('contingency', 'etg', 'qlearning', 'tg')
    >>> learners("worlds")
    ('tg', 'ptg', 'qtable')
    >>> make_world_learner("tg").params["q_init"]
    0.0
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from typing import Any, TypeVar

from relrl.errors import ConfigError, PrologError, RelrlError
from relrl.kb import layer_api
from relrl.learners.base import DOMAINS, FAMILIES, WORLDS, Learner, LearnerSpec, Parameter
from relrl.terms import Term, Var, format_term

__all__ = ["PrologLearner", "build_registry", "learner_spec", "learners", "make_learner",
           "make_world_learner", "register", "registry"]

#: seconds the catalogue's one call may take (it reads declarations only)
_TIMEOUT = 10.0

#: the Python side of learners, by name (register)
_CLASSES: dict[str, type[Learner]] = {}

L = TypeVar("L", bound=type[Learner])


def register(cls: L) -> L:
    """Class decorator: ``cls`` is the Python side of the learner ``cls.name`` (a learner
    of relrl's Prolog, or with ``python_spec`` one that chooses in Python)."""
    if not cls.name:
        raise RelrlError(f"{cls.__qualname__} names no learner")
    _CLASSES[cls.name] = cls
    return cls


class PrologLearner(Learner):
    """A learner declared in Prolog alone: everything it does runs there; its
    explanation's detail is reported as text."""

    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """``detail``: the learner's own part of its explanation, as Prolog text."""
        return {"detail": format_term(detail)}


def catalogue() -> list[Term]:
    """Prolog's answer: ``learner(Name, Properties, Parameters, Serves)`` for every learner
    (``relrl_learners:learner_catalogue/1``).

    Raises:
        ConfigError: a learner's declarations are wrong (names the learner and what).
    """
    try:
        out = layer_api("learners", Var(), timeout=_TIMEOUT)
    except PrologError as exc:
        formal = exc.term[1] if isinstance(exc.term, tuple) and exc.term[0] == "error" \
            else exc.term
        if isinstance(formal, tuple) and formal[0] == "learner_declaration":
            raise ConfigError(f"{exc.message} (the learners' declarations, "
                              "prolog/learners.pl)") from None
        raise
    if out is None:
        raise RelrlError("relrl_learners:learner_catalogue/1 failed")
    return list(out[0])


def build_registry(entries: list[Term], classes: Mapping[str, type[Learner]]
                   ) -> dict[str, tuple[LearnerSpec, type[Learner]]]:
    """The registry from Prolog's catalogue ``entries`` and the Python ``classes``: every
    learner of Prolog but the external ones, made by its class or :class:`PrologLearner`,
    and in an external one's place the classes with a ``python_spec`` choosing through it
    (by name); in the catalogue's order.

    Raises:
        RelrlError: a class names a learner Prolog does not declare, or a Python learner's
            engine is not an external learner of Prolog.
    """
    found: dict[str, tuple[LearnerSpec, type[Learner]]] = {}
    for _, name, properties, parameters, serves in entries:
        props = tuple(format_term(p) for p in properties)
        if "external" in props:
            for python_name, cls in sorted(classes.items()):
                if cls.python_spec is not None and cls.python_spec.engine == name:
                    found[python_name] = (cls.python_spec, cls)
            continue
        spec = LearnerSpec(name=str(name), engine=str(name),
                           parameters=tuple(_parameter(str(name), p) for p in parameters),
                           serves={str(f): {str(o[1]): float(o[2]) for o in overrides}
                                   for _, f, overrides in serves})
        _check_values(spec)
        cls = classes.get(spec.name, PrologLearner)
        if cls.python_spec is not None:
            raise RelrlError(f"learner {spec.name!r} is declared both in Prolog and in Python "
                             f"({cls.__qualname__}.python_spec)")
        found[spec.name] = (spec, cls)
    for name, cls in classes.items():
        if name in found:
            continue
        spec = cls.python_spec
        if spec is None:
            raise RelrlError(f"{cls.__qualname__} is the Python side of learner {name!r}, "
                             "which relrl's Prolog does not declare (prolog/learners.pl)")
        raise RelrlError(f"learner {name!r} chooses through Prolog learner {spec.engine!r}, "
                         "which is not an external learner of relrl's Prolog")
    for spec, _ in found.values():
        for family in spec.serves:
            if family not in FAMILIES:
                raise RelrlError(f"learner {spec.name!r} serves {family!r}, not a family of "
                                 f"tasks ({', '.join(FAMILIES)})")
    return found


def _parameter(learner: str, term: Term) -> Parameter:
    _, name, default, kind = term
    try:
        if isinstance(kind, tuple) and len(kind) == 2 and isinstance(kind[1], int):
            return Parameter(str(name), float(default), str(kind[0]), kind[1])  # whole(Min)
        return Parameter(str(name), float(default), str(kind))
    except ValueError as exc:                 # an unknown kind
        raise _declaration_error(learner, str(exc)) from None


def _check_values(spec: LearnerSpec) -> None:
    """Every default and override of ``spec`` is a value of its parameter's kind (the one
    check of kinds: Prolog checks the declarations' structure)."""
    by_name = {p.name: p for p in spec.parameters}
    values = [(p, p.default) for p in spec.parameters]
    values += [(by_name[n], v) for overrides in spec.serves.values()
               for n, v in overrides.items()]
    for p, v in values:
        if not p.holds(v):
            raise _declaration_error(spec.name, f"parameter {p.name}: {v:g} is not "
                                                f"{p.allowed}")


def _declaration_error(learner: str, problem: str) -> ConfigError:
    return ConfigError(f"learner {learner}: {problem} (the learners' declarations, "
                       "prolog/learners.pl)")


@functools.cache
def registry() -> dict[str, tuple[LearnerSpec, type[Learner]]]:
    """Every learner by name: its spec and the class that makes it (asked of Prolog once
    per process; :func:`build_registry`)."""
    return build_registry(catalogue(), _CLASSES)


def learners(family: str | None = None) -> tuple[str, ...]:
    """The names of the learners serving ``family`` (``domains`` or ``worlds``; None:
    every learner), in the registry's order (prolog/learners.pl's)."""
    return tuple(name for name, (spec, _) in registry().items()
                 if family is None or family in spec.serves)


def learner_spec(name: str) -> LearnerSpec:
    """The spec of learner ``name``.

    Raises:
        ConfigError: no learner of that name.
    """
    try:
        return registry()[name][0]
    except KeyError:
        raise ConfigError(f"unknown learner {name!r} (known: "
                          f"{', '.join(learners())})") from None


def make_learner(name: str, **params: float) -> Learner:
    """The learner ``name`` of the domains with ``params`` over its defaults.

    Raises:
        ConfigError: unknown learner (or not one of the domains) or parameter.
    """
    return _make(name, DOMAINS, params)


def make_world_learner(name: str, **params: float) -> Learner:
    """The learner ``name`` of worlds with ``params`` over its defaults in worlds
    (``learner_serves(Name, worlds, Overrides)``).

    Raises:
        ConfigError: unknown learner (or not one of worlds) or parameter.
    """
    return _make(name, WORLDS, params)


def _make(name: str, family: str, params: Mapping[str, float]) -> Learner:
    entry = registry().get(name)
    if entry is None or family not in entry[0].serves:
        known = ", ".join(learners(family))
        if entry is not None:
            tasks = "the domains" if family == DOMAINS else family
            raise ConfigError(f"learner {name!r} does not learn {tasks} (learners of "
                              f"{tasks}: {known})")
        if family == DOMAINS:
            raise ConfigError(f"unknown learner {name!r} (known: {known})")
        raise ConfigError(f"unknown learner {name!r} for a world (learners of worlds: "
                          f"{known})")
    spec, cls = entry
    return cls(spec, family, **params)
