"""An interactive prompt over a live knowledge base (``relrl shell``), with swipl's habits.

Type a Prolog query at ``?-``; a query may span lines and ends with a full stop. As at the
swipl toplevel, answers come one at a time: after an answer that may have others, type ``;``
(or space, ``n``, ``r``, tab) for the next, Enter (or ``.``, ``c``, ``a``) to stop, ``w`` to
see the answer's terms whole, ``p`` to see them to depth 10 again, ``h`` for help. Output the
query writes (``write/1``, ``format/2``) comes in order with the answers. ``make.`` reloads
the domain files that changed on disk; ``trace.`` traces the domain's predicates (every
port, without stopping: see :data:`TRACE_NOTE`). Lines starting with ``:`` are shell commands
(``:help``).

Every query runs under a time limit (``--timeout``, ``:set timeout``; per answer), which can
be changed but not switched off.

The shell reads piped input too (``echo "response(R)." | relrl shell fruits.pl``): then it
prints no prompt and every answer of each query (up to ``--max``).
"""

from __future__ import annotations

import math
import os
import re
import sys
import tempfile
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from relrl.errors import ConfigError, PrologLoadError, RelrlError, UserError
from relrl.kb import KnowledgeBase
from relrl.query import OpenQuery
from relrl.terms import format_term

__all__ = ["Shell", "COMMANDS", "command", "check_timeout"]

HISTORY = Path(os.environ.get("RELRL_HISTORY", Path.home() / ".relrl_history"))

#: what the shell says about the tracer.
TRACE_NOTE = ("relrl shell traces without stopping (it runs SWI-Prolog embedded, with no "
              "interactive tracer); for the interactive tracer, load the domain in plain "
              "SWI-Prolog (relrl examples shows the command)")

#: keys after an answer, as at the swipl toplevel.
_NEXT_KEYS = frozenset(";nr \t")
_STOP_KEYS = frozenset("\r\n.ca\x04")
_HELP = ("  ; (n, r, space, tab): next answer   c (a, Enter, .): stop\n"
         "  w: write the answer's terms whole    p: print them to depth 10\n"
         "  h (?): this help")

#: [user] and consult(user): clauses typed after them, as at swipl's toplevel.
_USER = re.compile(r"^(\[\s*'?user'?\s*\]|consult\(\s*'?user'?\s*\))$")
#: spy(Spec) and nospy(Spec): trace points instead of spy points.
_SPY = re.compile(r"^(no)?spy\((.+)\)$", re.S)
#: goals that switch swipl's interactive debugger on or off: answered by the shell.
_DEBUGGER = {"trace": "trace", "notrace": "notrace", "nodebug": "notrace",
             "debug": "debugger", "gtrace": "debugger", "guitracer": "debugger",
             "tracemode": "debugger"}


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


def check_timeout(value: object, flag: str | None = None) -> float:
    """A time limit in seconds: a positive, finite number (``flag``: the command-line
    flag that gave it, named in the error).

    Raises:
        ConfigError: anything else (0, a negative number, nan, inf, text): the limit of a
            user's query (or of a run's rules) cannot be switched off.
    """
    try:
        seconds = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        seconds = math.nan
    if isinstance(value, bool) or not 0 < seconds < math.inf:
        where = f"{flag}: " if flag else ""
        raise ConfigError(f"{where}time limit {value!r}: use a positive number of seconds "
                          "(a query's time limit cannot be switched off)")
    return seconds


class _Terminal:
    """Reads one key at a time from the terminal, without Enter and without echo (cbreak
    mode, set before the answer is written so that no key typed after it is lost)."""

    def __init__(self) -> None:
        self._fd = sys.stdin.fileno()
        self._saved: list | None = None

    def __enter__(self) -> _Terminal:
        import termios
        import tty

        self._saved = termios.tcgetattr(self._fd)
        tty.setcbreak(self._fd, termios.TCSANOW)   # TCSANOW: keep keys typed ahead
        return self

    def __exit__(self, *exc: object) -> None:
        import termios

        if self._saved is not None:
            termios.tcsetattr(self._fd, termios.TCSANOW, self._saved)
            self._saved = None

    def __call__(self) -> str:
        """One key ("" at end of input)."""
        return os.read(self._fd, 1).decode("utf-8", errors="replace")


class Shell:
    """The read-query-print loop over one knowledge base.

    Args:
        kb: the knowledge base to query.
        out: where answers go.
        max_solutions: how many answers of a query to print at most when reading piped
            input (at a terminal, the user asks for each answer).
        timeout: seconds each answer may take (positive; see :func:`check_timeout`).
        keys: where the interactive loop reads the key typed after an answer (default: the
            terminal, one key without Enter; a context manager around each answer).
    """

    def __init__(self, kb: KnowledgeBase, out: TextIO | None = None, *,
                 max_solutions: int = 100, timeout: float = 10.0,
                 keys: Callable[[], str] | None = None) -> None:
        self.kb = kb
        self.out = sys.stdout if out is None else out  # the stdout of now, not of import
        self.max_solutions = max_solutions
        self.timeout = check_timeout(timeout)
        self.keys = keys
        self.mode = "print"          # how answers write terms: "print" (depth 10) or "write"
        self.errors = 0
        self.done = False
        self.interactive = False
        self.policy = None  # set by relrl.policy when a learned policy is loaded
        self.loaded: dict[Path, float] = {}   # domain files -> their modification time
        #: where the lines typed after [user] come from (set by the loops; None: nowhere)
        self.more_lines: Callable[[], str | None] | None = None
        self._user_dir: tempfile.TemporaryDirectory | None = None   # holds user.pl
        for path in kb.files:
            self._note_loaded(path)

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
            else:
                goal = text.rstrip().rstrip(".").strip()
                if goal in ("halt", "quit", "exit"):
                    self.done = True
                elif goal == "make":
                    self.make()
                    self._answer_line("true.")
                elif goal in _DEBUGGER:
                    self._debugger(_DEBUGGER[goal])
                elif _SPY.match(goal):
                    self._spy(goal)
                elif _USER.match(goal):
                    self.consult_user()
                else:
                    self._query(text)
        except RelrlError as exc:
            self.errors += 1
            self.print(f"error: {exc}")
        if self.interactive:
            self.print("")

    def _query(self, text: str) -> None:
        self.flush()
        with self.kb.open_query(text, timeout=self.timeout, mode=self.mode) as query:
            if self.interactive:
                self._answers_one_at_a_time(query)
            else:
                self._all_answers(query)

    def _all_answers(self, query: OpenQuery) -> None:
        """Piped input: every answer (up to max_solutions), each printed as soon as it is
        found (``X = a ;``), as if the user typed ``;`` after each."""
        answer = query.next()
        shown = 0
        while answer is not None:
            shown += 1
            text = answer.text or "true"
            if answer.last:
                self._answer_line(text + ".")
                return
            self._answer_line(text + " ;")
            if shown == self.max_solutions:
                self.print(f"... (more than {self.max_solutions} answers; see :set max N)")
                return
            self.flush()
            answer = query.next()
        self._answer_line("false.")

    def _answers_one_at_a_time(self, query: OpenQuery) -> None:
        """At a terminal: show an answer, then wait for ; or Enter, as swipl does."""
        answer = query.next()
        if answer is None:
            self._answer_line("false.")
            return
        while answer is not None:
            text = answer.text or "true"
            if answer.last:
                self._answer_line(text + ".")
                return
            key = self._ask(text + " ")
            while key not in _NEXT_KEYS and key not in _STOP_KEYS:
                if key in "wp":
                    self.mode = "write" if key == "w" else "print"
                    self.write(f"[{self.mode}]\n")
                    answer = query.again(self.mode)
                    if answer is None:
                        return
                    text = answer.text or "true"
                    key = self._ask(text + " ")
                elif key in "h?":
                    key = self._ask("\n" + _HELP + "\n" + text + " ")
                elif key == "t":
                    key = self._ask(f"\n% no trace&redo: {TRACE_NOTE}\nAction? ")
                else:
                    key = self._ask(f"\nunknown action {key!r} (h for help)\nAction? ")
            if key in _STOP_KEYS:
                self.write(".\n")
                return
            self.write(";\n")
            self.flush()
            answer = query.next()
            if answer is None:
                self._answer_line("false.")

    def _ask(self, text: str) -> str:
        """Write ``text`` and read the key the user types after it (end of input or
        Ctrl-C: stop)."""
        try:
            if self.keys is not None:
                self.write(text)
                return self.keys() or "\x04"
            with _Terminal() as terminal:
                self.write(text)
                return terminal() or "\x04"
        except KeyboardInterrupt:
            return "\x04"

    def _answer_line(self, text: str) -> None:
        self.print(text)

    # -- make, the debugger ----------------------------------------------------------------

    def _note_loaded(self, path: str | os.PathLike) -> None:
        p = Path(path).resolve()
        try:
            self.loaded[p] = p.stat().st_mtime
        except OSError:
            self.loaded[p] = 0.0

    def load(self, path: str | os.PathLike) -> None:
        """Load a domain file all or nothing: a file with an error loads nothing.

        The file is first loaded, after the files already loaded, into a scratch knowledge
        base; only when that succeeds is it loaded into this one.

        Raises:
            PrologLoadError: the file has an error (or, the shell being strict, a warning).
        """
        self._check_files([*(p for p in self.loaded if p.exists()), Path(path)],
                          "nothing loaded")
        self.kb.load(path)
        self._note_loaded(path)

    def consult_user(self) -> None:
        """``[user].``: read clauses from the input up to its end (Ctrl-D at a terminal) or a
        line ``end_of_file.``, then load them into the domain all or nothing, as a file
        named ``user`` (typed again, they replace the clauses typed before, as in swipl).

        Raises:
            UserError: no input to read clauses from.
            PrologLoadError: the clauses have an error (nothing is loaded); it names
                ``user`` and the line.
        """
        if self.more_lines is None:
            raise UserError("[user] reads clauses from the input, and this shell has none")
        if self.interactive:
            self.print("% type clauses; end with Ctrl-D or end_of_file.")
        lines = []
        while (line := self.more_lines()) is not None and line.strip() != "end_of_file.":
            lines.append(line if line.endswith("\n") else line + "\n")
        if self._user_dir is None:
            self._user_dir = tempfile.TemporaryDirectory(prefix="relrl-user-")
        path = Path(self._user_dir.name) / "user.pl"
        path.write_text("".join(lines))
        try:
            self._check_files([*(p for p in self.loaded if p.exists()), path], "nothing loaded")
            self.kb.load(path)
        except PrologLoadError as exc:
            shown = str(path)
            raise PrologLoadError("user", exc.line, exc.text.replace(shown, "user"),
                                  [("user" if f == shown else f, n, t.replace(shown, "user"))
                                   for f, n, t in exc.problems]) from None
        self._answer_line("true.")

    def make(self) -> list[Path]:
        """Reload the loaded domain files that changed on disk (swipl's ``make/0``).

        A changed file with an error is not reloaded: its last good version stays.

        Returns:
            The files reloaded.
        """
        changed = []
        for path, mtime in self.loaded.items():
            try:
                now = path.stat().st_mtime
            except OSError:
                self.print(f"% {_shown(path)}: no longer there (its clauses stay)")
                continue
            if now != mtime:
                changed.append(path)
        if not changed:
            return []
        self._check_files([p for p in self.loaded if p.exists()],
                          "not reloaded: its last good version stays")
        for path in changed:
            self.kb.load(path)
            self._note_loaded(path)
            self.print(f"% {_shown(path)} reloaded")
        return changed

    def _check_files(self, paths: list[Path], outcome: str) -> None:
        """Load ``paths`` into a scratch knowledge base; a load error names ``outcome``."""
        scratch = KnowledgeBase(timeout=self.kb.timeout)
        try:
            for p in paths:
                try:
                    scratch.load(p)
                except PrologLoadError as exc:
                    raise PrologLoadError(exc.path, exc.line, f"{exc.text} ({outcome})",
                                          exc.problems) from None
        finally:
            scratch.close()

    def _debugger(self, what: str) -> None:
        if what == "trace":
            self._quietly(_TRACE_ALL)
            self.print("% tracing every port of the domain's rules (notrace. stops; "
                       "trace(Name/Arity) traces one predicate)")
            self.print(f"% {TRACE_NOTE}")
        elif what == "notrace":
            self._quietly(_TRACE_NONE)
            self.print("% tracing stopped")
        else:
            self.print(f"% not available: {TRACE_NOTE}")
            self.print("% here trace. prints every port of the domain's rules, "
                       "trace(Name/Arity) those of one predicate")

    def _spy(self, goal: str) -> None:
        match = _SPY.match(goal)
        assert match is not None
        off, spec = match.group(1), match.group(2)
        self._quietly(f"trace({spec}, {'-' if off else '+'}all)")
        self.print(f"% {'no longer tracing' if off else 'tracing every port of'} {spec} "
                   f"(spy points stop in the interactive tracer, which relrl shell does not "
                   f"have: it traces without stopping)")

    def _quietly(self, text: str) -> None:
        """Run a goal of the shell's own (its answer is not shown; errors are)."""
        with self.kb.open_query(text, timeout=self.timeout) as query:
            if query.next() is None:
                raise UserError(f"{text} failed")

    # -- output ----------------------------------------------------------------------------

    def print(self, text: str) -> None:
        """Write a line of output."""
        print(text, file=self.out)

    def write(self, text: str) -> None:
        """Write text (no newline added) and flush it."""
        self.out.write(text)
        self.flush()

    def flush(self) -> None:
        """Flush the output, so that it comes before what Prolog writes next."""
        try:
            self.out.flush()
        except (OSError, ValueError):
            pass

    def parse_terms(self, text: str) -> list:
        """Read comma-separated Prolog terms from ``text`` (nothing is run)."""
        from relrl.engine import one

        return one(self.kb, "parse", self.kb.module, text.rstrip(". "))

    # -- loops -----------------------------------------------------------------------------

    def run_lines(self, lines: Iterable[str]) -> None:
        """Execute inputs from an iterable of lines (piped input, a script)."""
        buffer = ""
        source = iter(lines)
        self.more_lines = lambda: next(source, None)
        for line in source:
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

    def _execute_at_terminal(self, text: str) -> None:
        """Ctrl-C stops the query at once and returns to the prompt, as at swipl's
        toplevel."""
        try:
            with self.kb.interruptible():
                self.execute(text)
        except KeyboardInterrupt:
            self.print("\n% interrupted\n")

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
        self.interactive = True
        self.more_lines = _typed_line
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
                    self._execute_at_terminal(stripped)
                    continue
                buffer += line + "\n"
                if stripped.endswith("."):
                    self._execute_at_terminal(buffer)
                    buffer = ""
        finally:
            self.interactive = False
            if readline is not None:
                try:
                    readline.write_history_file(HISTORY)
                except OSError:
                    pass


#: queries run in the knowledge base's module: trace points on every rule the domain defines
#: (not its declarations, but its constraint rules), and every trace point off again.
_DOMAIN_PREDICATE = ("current_predicate(N/A), functor(H, N, A), "
                     "\\+ predicate_property(H, imported_from(_)), "
                     "\\+ predicate_property(H, built_in), "
                     "\\+ predicate_property(H, number_of_clauses(0)), "
                     "( N/A == forbidden/1 -> true "
                     "; \\+ relrl_declarations:declaration_predicate(N/A) )")
_TRACE_ALL = f"forall(({_DOMAIN_PREDICATE}), trace(N/A, +all))"
_TRACE_NONE = "notraceall"


def _typed_line() -> str | None:
    """A line typed after ``[user].`` (at swipl's ``|:`` prompt); None at end of input."""
    try:
        return input("|: ")
    except EOFError:
        return None


def _shown(path: Path) -> str:
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


# -- built-in commands ---------------------------------------------------------------------

@command("help", ":help", "list the commands")
def _help(shell: Shell, _: str) -> None:
    shell.print("Type a Prolog query ending with a full stop, e.g.  stimulus(S).  After an "
                "answer: ; next, Enter stop, h help. make. reloads changed files.")
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
    from relrl.validate import unread_percepts

    for term in unread_percepts(shell.kb, terms):
        shell.print(f"warning: {format_term(term)} is not a percept of this domain: no "
                    f"stimulus, fact or rule perceives it (a typo?)")


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


@command("load", ":load FILE", "load another domain file (all or nothing)")
def _load(shell: Shell, text: str) -> None:
    if not text:
        raise UserError("usage: :load FILE")
    shell.load(text)
    shell.print(f"loaded {text}")


@command("set", ":set max N | timeout S | answers write|print",
         "answers shown per piped query; time limit per answer; how answers write terms")
def _set(shell: Shell, text: str) -> None:
    key, _, value = text.partition(" ")
    value = value.strip()
    if key == "timeout":
        shell.timeout = check_timeout(value)
        shell.print(f"timeout = {shell.timeout:g} s per answer")
    elif key == "max":
        try:
            n = int(value)
        except ValueError:
            n = 0
        if n < 1:
            raise ConfigError(f":set max {value}: use a whole number >= 1")
        shell.max_solutions = n
        shell.print(f"max = {n} answers per piped query")
    elif key == "answers" and value in ("write", "print"):
        shell.mode = value
        shell.print(f"answers = {value}")
    else:
        raise UserError(f"usage: :set max N | :set timeout SECONDS | :set answers write|print "
                        f"(got {text!r})")
