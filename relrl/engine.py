"""The one typed front over relrl's Prolog engine.

Every goal of relrl's Prolog that Python calls is called by its short name, as
``prolog/gateway.pl``'s ``python_api/2`` declares it (the one list, asked when Prolog
starts; the gateway refuses any other goal of relrl's modules). Results come back decoded:
:meth:`Engine.step` returns a :class:`StepResult` dataclass, not a term to unpack by
position, and a goal that fails where it must succeed raises :class:`EngineError` naming it.

One :class:`Engine` serves one knowledge base. The control loop (:mod:`relrl.loop`) and the
learners (:mod:`relrl.learners`) use it; so can a researcher embedding relrl:

Example:
    >>> from relrl.kb import KnowledgeBase
    >>> from relrl.engine import Engine
    >>> kb = KnowledgeBase("examples/domains/sis.pl")
    >>> engine = Engine(kb)
    >>> engine.configure("etg", {"alpha": 0.2, "gamma": 0.9, "epsilon": 0.05,
    ...                          "q_init": 30.0, "split_threshold": 0.1,
    ...                          "reward_positive": 10.0, "reward_negative": -1.0}, seed=0)
    >>> r = engine.step([("see", "face"), ("pose", "face", "frontal"), ("at", "centre")])
    >>> engine.responses[r.action_index]
    ('look', 'centre')
"""

from __future__ import annotations

import contextlib
import itertools
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from relrl.bridge.marshal import Cached
from relrl.errors import EngineError, PolicyError, PrologError, QueryTimeout
from relrl.outdir import write_atomic
from relrl.terms import Term, Var

if TYPE_CHECKING:
    from relrl.kb import KnowledgeBase

__all__ = ["ALL_ALLOWED", "MODES", "WANTS", "Engine", "EngineError", "StepResult",
           "mask_indices", "POLICY_BYTES_PER_POSITION", "POLICY_SECONDS_PER_MB"]

#: seconds a policy load may take per megabyte of the file, on top of the knowledge base's
#: time limit (a policy runs no rule of its own: its load is bounded by its size; about
#: five times what a loaded 2-core machine needs).
POLICY_SECONDS_PER_MB = 2.0
#: what a position of learned knowledge (a node, an entry, a rule) takes in a policy file,
#: at most, for the time a save may take (measured: 35 to 60 bytes).
POLICY_BYTES_PER_POSITION = 100

#: The allowed mask of a step at which every response is allowed (a domain without
#: constraint rules): the engine does not build a mask of as many bits every step.
ALL_ALLOWED = -1

#: Step modes: update the learner and explore, explore without learning, or neither.
MODES = ("learn", "explore", "greedy")
#: What a step can report besides its result, in the same call.
WANTS = ("memory", "memory_size", "explain")

_slots = itertools.count()


@dataclass(frozen=True, slots=True)
class StepResult:
    """What one control step (``relrl_engine:engine_step/6``) reports."""

    code: int                     #: the state code, sum of 2^x (0 for a relational learner)
    necessity: str                #: the active necessity, or "none"
    outputs: tuple[float, ...]    #: every necessity unit's output, in declaration order
    reward: float                 #: the reward for the previous response
    reinforced: bool              #: a reinforcer was perceived this step
    allowed_mask: int             #: bit i set when response i is allowed
    action_index: int             #: the learner's choice (index), -1 for none / Python learner
    memory: tuple[tuple[int, Term], ...] | None = None   #: (age, element), when asked
    memory_size: int | None = None                        #: when asked
    explanation: Term | None = None                       #: the learner's, when asked

    @property
    def allowed_index(self) -> list[int]:
        """Indices of the allowed responses, in declaration order."""
        return mask_indices(self.allowed_mask)


def mask_indices(mask: int) -> list[int]:
    """The indices of the bits set in an allowed-responses mask, in increasing order."""
    out, i = [], 0
    while mask:
        if mask & 1:
            out.append(i)
        mask >>= 1
        i += 1
    return out


def call(kb: KnowledgeBase, goal: str, *arguments: Term, timeout: float | None = None) -> list:
    """Call the goal of relrl's Prolog that ``python_api/2`` names ``goal`` once.

    Returns the values of its :class:`~relrl.terms.Var` arguments.

    Raises:
        EngineError: the goal failed.
    """
    return kb.api_det(goal, *arguments, timeout=timeout)


def call_semidet(kb: KnowledgeBase, goal: str, *arguments: Term,
                 timeout: float | None = None) -> list | None:
    """:func:`call` for a goal that may fail: None when it does."""
    return kb.api(goal, *arguments, timeout=timeout)


def one(kb: KnowledgeBase, goal: str, *arguments: Term) -> Term:
    """Call ``goal`` with ``arguments`` and one more output argument; return its value."""
    return call(kb, goal, *arguments, Var())[0]


class Engine:
    """The engine of one knowledge base: configure it, step it, ask it why.

    Args:
        kb: the knowledge base holding the domain.
    """

    def __init__(self, kb: KnowledgeBase) -> None:
        self.kb = kb
        self.module = kb.module
        self.learner: str | None = None
        self.responses: list[Term] = []
        self.necessities: list[str] = []

    # -- a run ------------------------------------------------------------------------------

    def configure(self, learner: str, params: Mapping[str, float], seed: int | None) -> None:
        """Start a run with the Prolog-side ``learner`` (``etg``, ``contingency``,
        ``external``, ...) and its ``params``; ``seed`` seeds this knowledge base's own random
        stream (None: from the clock). Working memory and the necessity units start afresh."""
        plist = [("=", k, v) for k, v in params.items()]
        call(self.kb, "configure", self.module, learner, plist,
             int(seed) if seed is not None else "none")
        self.learner = learner
        self.responses = one(self.kb, "responses", self.module)
        self.necessities = list(one(self.kb, "necessities", self.module))
        self.kb.hold([*self.necessities, "none"])

    def step(self, percepts: Sequence[Term] | Cached, emitted: int = -1, mode: str = "learn",
             want: Iterable[str] = ()) -> StepResult:
        """One control step: one gateway call (``relrl_gateway:gw_step/14``, the gateway's
        form of ``engine_step/6`` whose result Python reads field by field).

        Args:
            percepts: this time unit's perception facts (a list, or a :class:`Cached` one).
            emitted: index of the response emitted at the previous step, -1 for none.
            mode: one of :data:`MODES`.
            want: any of :data:`WANTS`, reported in the same call.
        """
        fields = self.step_fields(percepts, emitted, mode, want)
        if fields[5] == ALL_ALLOWED:
            fields = (*fields[:5], (1 << len(self.responses)) - 1, *fields[6:])
        return StepResult(*fields)

    def step_fields(self, percepts: Sequence[Term] | Cached, emitted: int = -1,
                    mode: str = "learn", want: Iterable[str] = ()) -> tuple:
        """:meth:`step`'s fields as a plain tuple, in :class:`StepResult`'s order (for
        the control loop, which builds its own record of the step), as the engine gives
        them: the allowed mask is :data:`ALL_ALLOWED` when every response is allowed."""
        if type(percepts) is not Cached:
            percepts = Cached(percepts if isinstance(percepts, list) else list(percepts))
        want = list(want) if want else []
        raw = self.kb.step(percepts, emitted, mode, want)
        if raw is None:
            raise EngineError(f"relrl_engine:engine_step/6 failed in {self.module}")
        code, necessity, ys, reward, reinforced, mask, action, extras = raw
        memory = memory_size = explanation = None
        if extras:
            for _, key, value in extras:
                if key == "memory":
                    memory = tuple((age, element) for (_, age, element) in value)
                elif key == "memory_size":
                    memory_size = value
                else:
                    explanation = value
        return (code, necessity, tuple(ys), float(reward), reinforced, mask, action,
                memory, memory_size, explanation)

    def end_episode(self) -> None:
        """End an interaction: forget the last step, working memory and the units' state."""
        call(self.kb, "end_episode", self.module)

    # -- what the learner knows -------------------------------------------------------------

    def explain(self, when: str = "last") -> Term:
        """``explanation(Learner, State, Necessity, Detail)`` for the last step's state
        (``when="last"``) or the state in working memory now (``"now"``)."""
        return one(self.kb, "explain", self.module, when)

    def text(self) -> str:
        """The learner's knowledge as text ("" when it has no drawing)."""
        return one(self.kb, "text", self.module)

    def graph(self) -> dict[str, list[dict[str, Any]]]:
        """The learner's tree as ``{"nodes": [{id, kind, label}], "edges": [{from, to,
        branch}]}`` (empty lists for a learner without a tree)."""
        _, nodes, edges = one(self.kb, "graph", self.module)
        return {"nodes": [{"id": _node_id(i), "kind": k, "label": str(label)}
                          for (_, i, k, label) in nodes],
                "edges": [{"from": _node_id(a), "to": _node_id(b), "branch": br}
                          for (_, a, b, br) in edges]}

    def knowledge(self) -> list[Term]:
        """The learner's knowledge as terms (for contingency, its behaviour/4 rules)."""
        return one(self.kb, "knowledge", self.module)

    def size(self) -> tuple[int, dict[str, int]]:
        """``(positions, details)``: the learner's memory in the paper's positions and its
        own counts."""
        _, _, positions, details = one(self.kb, "size", self.module)
        return positions, {k: v for (_, k, v) in details}

    def relational_state(self) -> list[Term]:
        """The relational view of the state now (the domain's relation/1 facts)."""
        return one(self.kb, "relational_state", self.module)

    # -- files ------------------------------------------------------------------------------

    def policy_text(self, header: str) -> str:
        """The learned knowledge as the text of a policy file (``header`` as its comment).

        Making it is linear in what was learned: it may take the knowledge base's time limit
        plus :data:`POLICY_SECONDS_PER_MB` per megabyte the policy is expected to take
        (:data:`POLICY_BYTES_PER_POSITION` per position of :meth:`size`).
        """
        megabytes = self.size()[0] * POLICY_BYTES_PER_POSITION / 1e6
        return call(self.kb, "policy", self.module, header, Var(),
                    timeout=self.kb.timeout + POLICY_SECONDS_PER_MB * megabytes)[0]

    def save(self, path: str | Path, header: str) -> Path:
        """Write the learned knowledge as a readable policy file (:mod:`relrl.outdir`: atomic,
        never through a link; the text as :meth:`policy_text` makes it)."""
        return write_atomic(path, self.policy_text(header))

    def load_policy(self, path: str | Path) -> None:
        """Replace the learned knowledge by the policy at ``path``, read as data.

        Reading and checking a policy is linear in its size (at most 16 MB, see
        prolog/policy.pl), so it may take the knowledge base's time limit plus
        :data:`POLICY_SECONDS_PER_MB` for each megabyte of the file.

        Raises:
            PolicyError: the file is not this learner's policy for this domain (file:line),
                or holds a term nested too deep to read, or reading it took longer than that.
        """
        try:
            size = Path(path).stat().st_size
        except OSError:
            size = 0  # policy_load names the missing file
        limit = self.kb.timeout + POLICY_SECONDS_PER_MB * size / 1e6
        try:
            with _readable(path):
                call(self.kb, "policy_load", self.module, str(path), timeout=limit)
        except QueryTimeout as exc:
            if exc.rule is not None:   # a rule of the domain never ended: its message names it
                raise
            raise PolicyError(f"{path}: reading the policy took longer than {limit:.0f} s "
                              f"({size / 1e6:.1f} MB); nothing was loaded") from None

    # -- evaluation without side effects ----------------------------------------------------

    def keep(self) -> str:
        """Save working memory, the units, the last step, the random stream and the
        learner's episode state inside Prolog; returns the slot for :meth:`resume`."""
        slot = f"s{next(_slots)}"
        call(self.kb, "keep", self.module, slot)
        return slot

    def resume(self, slot: str) -> None:
        """Restore what :meth:`keep` saved in ``slot`` (once)."""
        call(self.kb, "resume", self.module, slot)

    def reseed(self, seed: int) -> None:
        """Seed this knowledge base's random stream."""
        call(self.kb, "reseed", self.module, int(seed))


def policy_learner(kb: KnowledgeBase, path: str | Path) -> str:
    """The learner named by a saved policy's first term (read as data).

    Raises:
        PolicyError: not a relrl policy (file:line), or a term nested too deep to read.
    """
    with _readable(path):
        return one(kb, "policy_learner", str(path))


@contextlib.contextmanager
def _readable(path: str | Path) -> Iterator[None]:
    """Within the block, a term of the file at ``path`` nested too deep for the C stack
    (reading it raised, as it does in plain swipl) is a :class:`PolicyError` naming it.
    A file that is not UTF-8 text, comments included, is refused before the block."""
    from relrl.textfile import not_utf8

    if (problem := not_utf8(path)) is not None:
        raise PolicyError(f"{path}:{problem[0]}: {problem[1]}")
    try:
        yield
    except PrologError as exc:
        term = exc.term
        if isinstance(term, tuple) and len(term) > 1 and term[1] == ("resource_error",
                                                                      "c_stack"):
            raise PolicyError(f"{path}: a term nested too deep to read (the C stack ran "
                              "out: some 10,000 levels)") from None
        raise


def _node_id(i: Term) -> str:
    if isinstance(i, tuple):  # nil(Parent, Branch): an empty branch
        return f"nil_{i[1]}_{i[2]}"
    return str(i)
