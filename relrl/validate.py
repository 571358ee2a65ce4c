"""Validating a loaded domain and describing its declarations (``relrl check``)."""

from __future__ import annotations

from relrl.bridge.calls import display_path as _display_path
from relrl.engine import call as engine_call
from relrl.engine import one
from relrl.errors import ConfigError
from relrl.kb import KnowledgeBase
from relrl.terms import Term, Var, format_term

__all__ = ["validate", "describe", "world_warnings", "bias_warnings", "unread_percepts",
           "vocabulary_terms"]


def validate(kb: KnowledgeBase) -> list[str]:
    """Return one line per problem in the domain of ``kb`` (empty when valid).

    Covers undefined predicates in rule bodies, responses used but not declared, duplicate
    declarations and bad necessity unit parameters (prolog/check.pl). Load warnings such as
    singleton variables come from :meth:`KnowledgeBase.load` with ``strict=False``.
    """
    out = engine_call(kb, "check_domain", kb.module, Var())
    lines = []
    for _, path, line, message in out[0]:  # type: ignore[index]
        where = f"{_display_path(path)}:{line}" if path else "domain"
        lines.append(f"{where}: {message}")
    return lines


def vocabulary_terms(world: str) -> list[Term]:
    """The percepts of a world (:mod:`perception.vocabulary`) as terms, a :class:`Var` for
    any value.

    Raises:
        ConfigError: no world of that name.
    """
    from perception.vocabulary import ANY
    from perception.vocabulary import world as vocabulary

    try:
        vocab = vocabulary(world)
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    return [tuple(Var() if a is ANY else a for a in t) for t in vocab.terms()]


def world_warnings(kb: KnowledgeBase, world: str) -> list[str]:
    """One line per fact of the domain that can never hold in ``world`` (its percepts lack
    one the fact's definition needs) and per stimulus the world never perceives.

    ``world`` names a vocabulary of :data:`perception.vocabulary.WORLDS` (``sis``,
    ``episodes``, ...).
    """
    lines = []
    for _, path, line, message in one(kb, "world_problems", kb.module,
                                      vocabulary_terms(world)):
        where = f"{_display_path(path)}:{line}" if path else "domain"
        lines.append(f"{where}: warning: {message} (world {world})")
    return lines


def bias_warnings(kb: KnowledgeBase) -> list[str]:
    """One line per warning about the tg learner's language bias: a ``#Type`` whose
    constants grow with the world (one per response's argument, or more than 10), which
    makes every leaf's candidate tests grow with it (prolog/tg_bias.pl)."""
    _, _, _, warnings = engine_call(kb, "bias_listing", kb.module,
                                Var())[0]  # type: ignore[index]
    return [f"{_display_path(path)}:{line}: warning: {message}" if path else
            f"domain: warning: {message}" for (_, path, line, message) in warnings]


def unread_percepts(kb: KnowledgeBase, percepts: list[Term]) -> list[Term]:
    """The ``percepts`` no stimulus, fact or rule of the domain perceives."""
    return one(kb, "unread_percepts", kb.module, list(percepts))


def describe(kb: KnowledgeBase) -> str:
    """A human-readable listing of the declarations of ``kb``."""
    lines = ["stimuli and facts (x, 2^x):"]
    for x, feature in enumerate(kb.features()):
        lines.append(f"  {x:3d} {1 << x:>12d}  {format_term(feature)}")
    reinforcers = engine_call(kb, "findall", kb.module,
                          ("stimulus_property", Var("S"), "reinforcer"), Var())[0]  # type: ignore
    if reinforcers:
        lines.append("reinforcers: " + ", ".join(format_term(r[1]) for r in reinforcers))
    lines.append("responses:")
    lines += [f"  {format_term(r)}" for r in kb.declarations("response")]
    lines.append("necessities:")
    for n in kb.declarations("necessity"):
        params = engine_call(kb, "findall", kb.module,
                         ("unit", n, Var("P"), Var("V")), Var())[0]  # type: ignore[index]
        text = ", ".join(f"{p[2]}={format_term(p[3])}" for p in params)
        lines.append(f"  {format_term(n)}: {text}")
        inputs = engine_call(kb, "necessity_inputs", kb.module, n, Var())[0]  # type: ignore
        for _, goal, weight in inputs:
            lines.append(f"      input {format_term(goal)}  weight {weight:+g}")
    rules = engine_call(kb, "rule_listing", kb.module, Var())[0]  # type: ignore[index]
    lines.append("rules:")
    lines += [f"  {r}" for r in rules] or ["  (none)"]
    lines += _bias_lines(kb)
    return "\n".join(lines)


def _bias_lines(kb: KnowledgeBase) -> list[str]:
    """The relational view and what the tg learner's language bias generates at the root."""
    _, relations, refinements, _ = engine_call(kb, "bias_listing", kb.module,
                                           Var())[0]  # type: ignore[index]
    if not relations and not refinements:
        return []
    lines = ["relations (the relational view, learner tg):"]
    lines += [f"  {r}" for r in relations] or ["  (none)"]
    lines.append(f"refinements of an empty tree (tg's candidate tests, {len(refinements)}):")
    lines += [f"  {r}" for r in refinements] or ["  (none: the domain declares no rmode/1)"]
    return lines
