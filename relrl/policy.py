"""Learned policies as files, and the shell commands that inspect them.

An ETG tree or a set of behaviour rules saves as a readable Prolog file (consult it in plain
swipl, or load it with ``relrl shell DOMAIN.pl --policy FILE``); a Q-table saves as ``.npz``.
"""

from __future__ import annotations

import json
from pathlib import Path

from relrl.errors import UserError
from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent
from relrl.shell import Shell, command
from relrl.terms import Term, format_term

__all__ = ["attach_learner", "load_policy", "not_a_policy_file", "policy_learner"]


def not_a_policy_file(path: str | Path) -> str | None:
    """What ``path`` is when it is no file a policy can be read from (``no such policy
    file``, ``a folder ...``, ``not a regular file ...``); ``None`` for a regular file."""
    path = Path(path)
    if path.is_file():
        return None
    if path.is_dir():
        return "a folder, not a policy file"
    if path.exists():
        return "not a regular file (a device, a pipe or a socket), not a policy file"
    return "no such policy file"


def policy_learner(path: str | Path, kb: KnowledgeBase) -> str:
    """The name of the learner that saved the policy file at ``path``."""
    path = Path(path)
    if (problem := not_a_policy_file(path)) is not None:
        raise UserError(f"{path}: {problem}")
    if path.suffix == ".npz":
        return "qlearning"
    from relrl.engine import policy_learner as read_learner

    return read_learner(kb, path)


def attach_learner(shell: Shell, name: str) -> Agent:
    """Give the shell an agent with a fresh learner called ``name``.

    A new learner starts a run, which empties working memory and restarts the necessity
    units; the shell then puts working memory back as it was, every element at its age, so
    that ``:explain`` and ``:step`` see what ``:add`` put there.
    """
    memory = shell.kb.memory()
    agent = Agent(shell.kb, make_learner(name), seed=0)
    restore_memory(shell.kb, memory)
    shell.policy = agent
    return agent


def restore_memory(kb: KnowledgeBase, memory: list[tuple[int, Term]]) -> None:
    """Put ``memory`` (``(age, element)`` pairs, as :meth:`KnowledgeBase.memory` gives them)
    back into an empty working memory: one insertion per age from the oldest, so that each
    element has its age again."""
    if not memory:
        return
    oldest = max(age for age, _ in memory)
    for age in range(oldest, -1, -1):
        kb.insert([element for a, element in memory if a == age])


def load_policy(shell: Shell, path: str | Path) -> Agent:
    """Load a saved policy into the shell's knowledge base (``relrl shell --policy``)."""
    name = policy_learner(path, shell.kb)
    agent = attach_learner(shell, name)
    agent.learner.load(path)
    shell.print(f"loaded {name} policy {path}")
    return agent


def _agent(shell: Shell) -> Agent:
    if shell.policy is None:
        raise UserError("no learner: start the shell with --policy FILE or --learner NAME, "
                        "or use :learner NAME")
    return shell.policy


@command("learner", ":learner NAME",
         "start a fresh learner (etg, tg, contingency, qlearning); working memory is kept, "
         "the necessity units start afresh")
def _learner(shell: Shell, text: str) -> None:
    name = text.strip() or "etg"
    attach_learner(shell, name)
    size = len(shell.kb.memory())
    shell.print(f"learner {name} ready (working memory kept: {size} element"
                f"{'s' if size != 1 else ''}; the necessity units start afresh)")


@command("tree", ":tree", "draw the learner's tree (etg, tg)")
def _tree(shell: Shell, _: str) -> None:
    text = _agent(shell).learner.tree()
    shell.print(text.rstrip() if text else "(this learner has no tree)")


@command("explain", ":explain", "why the learner would choose what it chooses now")
def _explain(shell: Shell, _: str) -> None:
    exp = _agent(shell).learner.explain(now=True)
    shell.print(f"state {exp.get('state')}  necessity {exp.get('necessity')}")
    for step in exp.get("path", []):
        bound = ", ".join(f"{k} = {v}" for k, v in step.get("bindings", {}).items())
        shell.print(f"  {step['test']} -> {'yes' if step['holds'] else 'no'}"
                    + (f"  ({bound})" if bound else ""))
    if "leaf" in exp:
        shell.print(f"  leaf {exp['leaf']}" if exp["leaf"] is not None else "  (null branch)")
    ranked = exp.get("ranked", [])
    if not ranked:
        shell.print("  no stored choices for this state and necessity: every response "
                    "starts equal")
    for item in ranked:
        value = {k: v for k, v in item.items() if k != "response"}
        shell.print(f"  {item['response']:<20} {json.dumps(value)}")


@command("step", ":step TERM, ...", "one control step with these percepts (no learning)")
def _step(shell: Shell, text: str) -> None:
    agent = _agent(shell)
    percepts = shell.parse_terms(text) if text else []
    out = agent.step(percepts, learning=False)
    ys = ", ".join(f"{n}={y:.3f}" for n, y in out.outputs.items())
    shell.print(f"state {out.code}  necessity {out.necessity} ({ys})  reward {out.reward:g}")
    shell.print(f"allowed: {', '.join(format_term(r) for r in out.allowed)}")
    shell.print(f"response: {format_term(out.action)}")


@command("save", ":save FILE", "save the learner's policy")
def _save(shell: Shell, text: str) -> None:
    if not text:
        raise UserError("usage: :save FILE")
    path = _agent(shell).learner.save(text)
    shell.print(f"saved {path}")
