"""An interactive prompt over a live knowledge base (``relrl shell``).

Type a Prolog query at ``?-`` and see every solution with its bindings written as Prolog
terms, as at the swipl top level. Lines starting with ``:`` are shell commands (``:help``).
A query may span lines; it ends with a full stop.

The shell reads piped input too (``echo "response(R)." | relrl shell fruits.pl``): then it
prints no prompt and every solution of each query.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from relrl.errors import RelrlError, UserError
from relrl.kb import KnowledgeBase
from relrl.terms import Var, format_term

__all__ = ["Shell", "COMMANDS", "command"]

HISTORY = Path(os.environ.get("RELRL_HISTORY", Path.home() / ".relrl_history"))


@dataclass
class _Command:
    name: str
    usage: str
    help: str
    func: Callable[[Shell, str], None]


#: Shell commands by name (``:name args``); other modules add theirs with :func:`command`.
COMMANDS: dict[str, _Command] = {}


def command(name: str, usage: str, help: str) -> Callable:
    """Register a shell command ``:name``; the function gets the shell and the argument text."""
    def register(func: Callable[[Shell, str], None]) -> Callable[[Shell, str], None]:
        COMMANDS[name] = _Command(name, usage, help, func)
        return func
    return register


class Shell:
    """The read-query-print loop over one knowledge base.

    Args:
        kb: the knowledge base to query.
        out: where answers go.
        max_solutions: how many solutions of a query to print at most.
        timeout: seconds a query may run.
    """

    def __init__(self, kb: KnowledgeBase, out: TextIO | None = None, *,
                 max_solutions: int = 100, timeout: float = 10.0) -> None:
        self.kb = kb
        self.out = sys.stdout if out is None else out  # the stdout of now, not of import
        self.max_solutions = max_solutions
        self.timeout = timeout
        self.errors = 0
        self.done = False
        self.policy = None  # set by relrl.policy when a learned policy is loaded

    # -- one input -------------------------------------------------------------------------

    def execute(self, text: str) -> None:
        """Run one complete input: a ``:command`` or a query ending with a full stop."""
        text = text.strip()
        if not text or text.startswith("%"):
            return
        try:
            if text.startswith(":"):
                name, _, rest = text[1:].partition(" ")
                cmd = COMMANDS.get(name)
                if cmd is None:
                    raise UserError(f"unknown command :{name} (try :help)")
                cmd.func(self, rest.strip())
            elif text.rstrip(".").strip() in ("halt", "quit", "exit"):
                self.done = True
            else:
                self._query(text)
        except RelrlError as exc:
            self.errors += 1
            self.print(f"error: {exc}")

    def _query(self, text: str) -> None:
        solutions, more = self.kb.query(text, max_solutions=self.max_solutions,
                                        timeout=self.timeout)
        if not solutions:
            self.print("false.")
            return
        for i, bindings in enumerate(solutions):
            last = i == len(solutions) - 1 and not more
            shown = [f"{name} = {printed}" for name, value, printed in bindings
                     if not (isinstance(value, Var) and printed == name)]
            body = ",\n".join(shown) if shown else "true"
            self.print(body + ("." if last else " ;"))
        if more:
            self.print(f"... (more than {self.max_solutions} solutions; "
                       f"see :set max N)")

    def print(self, text: str) -> None:
        """Write a line of output."""
        print(text, file=self.out)

    def parse_terms(self, text: str) -> list:
        """Read comma-separated Prolog terms from ``text`` (nothing is run)."""
        out = self.kb.call("relrl_gateway:gw_parse", self.kb.module, text.rstrip(". "), Var())
        return out[0]  # type: ignore[index]

    # -- loops -----------------------------------------------------------------------------

    def run_lines(self, lines: Iterable[str]) -> None:
        """Execute inputs from an iterable of lines (piped input, a script)."""
        buffer = ""
        for line in lines:
            stripped = line.strip()
            if not buffer and stripped.startswith(":"):
                self.execute(stripped)
            else:
                buffer += line
                if stripped.endswith("."):
                    self.execute(buffer)
                    buffer = ""
            if self.done:
                return
        if buffer.strip():
            self.execute(buffer)

    def interact(self) -> None:
        """Prompt at a terminal with line editing and history until :quit or end of input."""
        try:
            import readline
        except ImportError:  # pragma: no cover - not on every platform
            readline = None  # type: ignore[assignment]
        if readline is not None:
            try:
                readline.read_history_file(HISTORY)
            except OSError:
                pass
        self.print(f"relrl shell on {self.kb} — :help for commands, :quit to leave")
        buffer = ""
        try:
            while not self.done:
                try:
                    line = input("?- " if not buffer else "|    ")
                except EOFError:
                    self.print("")
                    break
                except KeyboardInterrupt:
                    self.print("")
                    buffer = ""
                    continue
                stripped = line.strip()
                if not buffer and stripped.startswith(":"):
                    self.execute(stripped)
                    continue
                buffer += line + "\n"
                if stripped.endswith("."):
                    self.execute(buffer)
                    buffer = ""
        finally:
            if readline is not None:
                try:
                    readline.write_history_file(HISTORY)
                except OSError:
                    pass


# -- built-in commands ---------------------------------------------------------------------

@command("help", ":help", "list the commands")
def _help(shell: Shell, _: str) -> None:
    shell.print("Type a Prolog query ending with a full stop, e.g.  stimulus(S).")
    for cmd in COMMANDS.values():
        shell.print(f"  {cmd.usage:<28} {cmd.help}")


@command("quit", ":quit", "leave the shell (also halt. or end of input)")
def _quit(shell: Shell, _: str) -> None:
    shell.done = True


@command("add", ":add TERM, ...", "insert percepts into working memory (one insertion)")
def _add(shell: Shell, text: str) -> None:
    if not text:
        raise UserError("usage: :add see(face), pose(face, frontal)")
    terms = shell.parse_terms(text)
    shell.kb.insert(terms)
    shell.print(f"inserted {len(terms)} element{'s' if len(terms) != 1 else ''}")


@command("memory", ":memory", "show working memory with ages")
def _memory(shell: Shell, _: str) -> None:
    items = shell.kb.memory()
    if not items:
        shell.print("(working memory is empty)")
    for age, element in items:
        shell.print(f"  age {age:<3d} {format_term(element)}")


@command("clear", ":clear", "empty working memory")
def _clear(shell: Shell, _: str) -> None:
    shell.kb.clear_memory()
    shell.print("working memory cleared")


@command("state", ":state [CODE]", "show the state code now (or decode CODE)")
def _state(shell: Shell, text: str) -> None:
    if text:
        try:
            code = int(text)
        except ValueError:
            raise UserError(f"not a state code: {text!r} (a non-negative integer)") from None
        terms = shell.kb.decode_state(code)
    else:
        code = shell.kb.state_code()
        terms = shell.kb.state_terms()
    shell.print(f"state {code}")
    features = shell.kb.features()
    for t in terms:
        x = features.index(t)
        shell.print(f"  x={x:<3d} 2^x={1 << x:<8d} {format_term(t)}")


@command("allowed", ":allowed", "the responses allowed now under the constraint rules")
def _allowed(shell: Shell, _: str) -> None:
    for r in shell.kb.allowed_responses():
        shell.print(f"  {format_term(r)}")


@command("load", ":load FILE", "consult another domain or policy file")
def _load(shell: Shell, text: str) -> None:
    shell.kb.load(text)
    shell.print(f"loaded {text}")


@command("set", ":set max N | :set timeout S", "solutions shown per query; query time limit")
def _set(shell: Shell, text: str) -> None:
    key, _, value = text.partition(" ")
    try:
        if key == "max":
            shell.max_solutions = max(1, int(value))
        elif key == "timeout":
            shell.timeout = float(value)
        else:
            raise ValueError
    except ValueError:
        raise UserError(f"usage: :set max N | :set timeout SECONDS (got {text!r})") from None
