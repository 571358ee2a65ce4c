"""``relrl shell``: answers as at the swipl toplevel (one at a time at a terminal, tested on a
pseudo-terminal), commands, piped input, make, :load all or nothing, trace, time limits."""

from __future__ import annotations

import io
import os
import re
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from relrl.kb import KnowledgeBase
from relrl.shell import Shell
from tests.conftest import FRUITS, ROOT, default_signals


@pytest.fixture
def shell():
    kb = KnowledgeBase(FRUITS)
    out = io.StringIO()
    sh = Shell(kb, out, timeout=0.5)
    yield sh, out
    kb.close()


def test_query_prints_bindings(shell) -> None:
    sh, out = shell
    sh.run_lines(["stimulus(S).\n"])
    assert out.getvalue() == ("S = face ;\nS = object ;\nS = attention ;\n"
                              "S = environment.\n")


def test_multi_line_query_and_compound_bindings(shell) -> None:
    sh, out = shell
    sh.run_lines(["fact(F),\n", "  F = looking_fruit(X).\n"])
    assert out.getvalue() == "F = looking_fruit(object),\nX = object.\n"


def test_true_and_false(shell) -> None:
    sh, out = shell
    sh.run_lines(["stimulus(face).\n", "stimulus(dog).\n"])
    assert out.getvalue() == "true.\nfalse.\n"


def test_percepts_memory_state(shell) -> None:
    sh, out = shell
    sh.run_lines([":add see(face), pose(face, frontal)\n", ":memory\n", ":state\n",
                  "see(frontal(face)).\n"])
    text = out.getvalue()
    assert "inserted 2 elements" in text
    assert "age 0   pose(face,frontal)" in text
    assert "state 129" in text
    assert text.endswith("true.\n")


@pytest.mark.slow
def test_errors_do_not_stop_the_shell(shell) -> None:
    sh, out = shell
    sh.run_lines(["repeat, fail.\n", "foo(.\n", ":nope\n", "stimulus(face).\n"])
    text = out.getvalue()
    assert "error: query ran longer than 0.5 s" in text
    assert "Syntax error" in text
    assert "unknown command :nope" in text
    assert text.endswith("true.\n")
    assert sh.errors == 3


def test_quit_stops(shell) -> None:
    sh, out = shell
    sh.run_lines([":quit\n", "stimulus(face).\n"])
    assert out.getvalue() == ""


@pytest.mark.slow
def test_piped_shell_process() -> None:
    proc = subprocess.run([sys.executable, "-m", "relrl.cli", "shell", str(FRUITS)],
                          input="response(R).\n", capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[0] == "R = look(centre) ;"
    assert proc.stdout.splitlines()[-1] == "R = name_object."


# -- the toplevel's habits (issue 14) -------------------------------------------------------

def _shell_proc(stdin: str, *args: str, domain: Path = FRUITS,
                timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "relrl.cli", "shell", str(domain), *args],
                          input=stdin, capture_output=True, text=True, cwd=ROOT,
                          timeout=timeout)


@pytest.mark.slow
def test_piped_output_comes_in_order_with_the_answers() -> None:
    proc = _shell_proc("write(a), X = 1 ; write(b), X = 2.\n"
                       "member(X, [1, 2]), format(\"hello ~w~n\", [X]).\n")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "aX = 1 ;\nbX = 2.\nhello 1\nX = 1 ;\nhello 2\nX = 2.\n"


@pytest.mark.slow
def test_a_choice_point_left_after_the_last_answer_reads_false() -> None:
    proc = _shell_proc("(X = 1 ; fail).\n")
    assert proc.stdout == "X = 1 ;\nfalse.\n"


@pytest.mark.slow
def test_cyclic_and_deep_answers_are_written_as_swipl_writes_them() -> None:
    proc = _shell_proc("X = f(X).\n"
                       "X = [a|X], Y = g(X, Y).\n"
                       "numlist(1, 100000, L), foldl([_, A, f(A)]>>true, L, a, T).\n"
                       "length(L, 3).\n")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines() == [
        "X = f(X).",
        "X = [a|X],", "Y = g(X, Y).",
        "L = [1, 2, 3, 4, 5, 6, 7, 8, 9|...],",
        "T = f(f(f(f(f(f(f(f(f(f(...)))))))))).",
        "L = [_, _, _]."]


def test_answers_write_whole_terms_on_request(shell) -> None:
    sh, out = shell
    sh.run_lines([":set answers write\n", "numlist(1, 12, L).\n", ":set answers print\n",
                  "numlist(1, 12, L).\n"])
    assert out.getvalue().splitlines() == [
        "answers = write", "L = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12].",
        "answers = print", "L = [1, 2, 3, 4, 5, 6, 7, 8, 9|...]."]


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf", "-inf", "soon", ""])
@pytest.mark.slow
def test_the_time_limit_cannot_be_switched_off(shell, value: str) -> None:
    sh, out = shell
    sh.run_lines([f":set timeout {value}\n", "repeat, fail.\n"])
    assert sh.timeout == 0.5
    lines = out.getvalue().splitlines()
    assert "cannot be switched off" in lines[0]
    assert lines[1] == "error: query ran longer than 0.5 s (a rule that never ends?)"


@pytest.mark.parametrize("value", ["-5", "0", "nan", "inf"])
@pytest.mark.slow
def test_timeout_flag_is_checked(value: str) -> None:
    proc = _shell_proc("true.\n", "--timeout", value)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.count("\n") == 1 and "--timeout" in proc.stderr
    assert "cannot be switched off" in proc.stderr


@pytest.mark.slow
def test_endless_answers_stop_at_max_when_piped() -> None:
    proc = _shell_proc("between(1, inf, X).\n", "--max", "3")
    assert proc.stdout.splitlines() == ["X = 1 ;", "X = 2 ;", "X = 3 ;",
                                        "... (more than 3 answers; see :set max N)"]


def test_load_is_all_or_nothing(shell, write_domain) -> None:
    sh, out = shell
    bad = write_domain("extra(1).\nextra(2).\nbroken(X) :- foo(.\nextra(3).\n", "bad.pl")
    good = write_domain("extra(10).\n", "good.pl")
    sh.run_lines([f":load {bad}\n", "catch(extra(X), E, (print_message(silent, E), fail)).\n",
                  f":load {good}\n", "extra(X).\n"])
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("error: ") and "bad.pl:3" in lines[0]
    assert "nothing loaded" in lines[0]
    assert lines[1] == "false."                # not one clause of bad.pl is there
    assert lines[2] == f"loaded {good}" and lines[3] == "X = 10."


def test_make_reloads_changed_files_and_keeps_a_broken_one(shell, write_domain) -> None:
    sh, out = shell
    extra = write_domain("extra(1).\n", "extra.pl")
    sh.run_lines([f":load {extra}\n", "make.\n", "extra(X).\n"])
    assert out.getvalue().splitlines()[1:] == ["true.", "X = 1."]
    out.truncate(0), out.seek(0)
    extra.write_text("extra(2).\nextra(3).\n")
    os.utime(extra, (1, 1))                    # a different time stamp, whatever the clock
    sh.run_lines(["make.\n", "extra(X).\n"])
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("% ") and lines[0].endswith("extra.pl reloaded")
    assert lines[1:] == ["true.", "X = 2 ;", "X = 3."]
    out.truncate(0), out.seek(0)
    extra.write_text("extra(4) :- .\n")
    os.utime(extra, (2, 2))
    sh.run_lines(["make.\n", "extra(X).\n"])
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("error: ") and "extra.pl:1" in lines[0]
    assert lines[0].endswith("(not reloaded: its last good version stays)")
    assert lines[1:] == ["X = 2 ;", "X = 3."]   # the last good version stays


@pytest.mark.slow
def test_trace_prints_the_ports_of_the_domain_rules() -> None:
    proc = _shell_proc("trace.\nlooking_frontal(face).\nnotrace.\nlooking_frontal(face).\n")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[0].startswith("% tracing every port")
    assert proc.stderr.splitlines() == [" T [6] Call: looking_frontal(face)",
                                        " T [6] Fail: looking_frontal(face)"]


def test_the_interactive_debugger_says_it_is_not_available(shell) -> None:
    sh, out = shell
    sh.run_lines(["debug.\n", "gtrace.\n"])
    assert out.getvalue().count("% not available:") == 2
    assert sh.errors == 0


# -- at a terminal: one answer at a time ----------------------------------------------------

class _Terminal:
    """A process on a pseudo-terminal: send keys, wait for text."""

    def __init__(self, args: list[str], env: dict[str, str]) -> None:
        import pty  # noqa: F401  (POSIX only, like the shell's key reading)

        self.master, slave = os.openpty()
        self.proc = subprocess.Popen(args, stdin=slave, stdout=slave, stderr=slave, env=env,
                                     cwd=ROOT, start_new_session=True,
                                     preexec_fn=default_signals)
        os.close(slave)
        self.seen = ""

    def expect(self, pattern: str, timeout: float = 120) -> str:
        """Wait for ``pattern`` (a regex); return the text up to its end and drop it."""
        end = time.monotonic() + timeout
        while True:
            m = re.search(pattern, self.seen)
            if m:
                text, self.seen = self.seen[:m.end()], self.seen[m.end():]
                return text.replace("\r\n", "\n")
            ready, _, _ = select.select([self.master], [], [], max(0, end - time.monotonic()))
            if not ready:
                raise AssertionError(f"{pattern!r} not seen; the terminal shows {self.seen!r}")
            try:
                self.seen += os.read(self.master, 4096).decode()
            except OSError:
                raise AssertionError(f"{pattern!r} not seen before the end: "
                                     f"{self.seen!r}") from None

    def quiet(self, seconds: float = 0.5) -> str:
        """What arrives within ``seconds`` (the process should be waiting for a key)."""
        ready, _, _ = select.select([self.master], [], [], seconds)
        return os.read(self.master, 4096).decode() if ready else ""

    def send(self, text: str) -> None:
        os.write(self.master, text.encode())

    def close(self) -> int:
        try:
            return self.proc.wait(120)
        finally:
            os.close(self.master)


@pytest.fixture
def terminal(tmp_path: Path):
    env = dict(os.environ, RELRL_HISTORY=str(tmp_path / "history"), TERM="dumb")
    term = _Terminal([sys.executable, "-m", "relrl.cli", "shell", "--timeout", "2",
                      str(FRUITS)], env)
    term.expect(r"\?- ")
    yield term
    if term.proc.poll() is None:
        term.proc.kill()
        term.close()


@pytest.mark.slow
def test_terminal_one_answer_at_a_time(terminal) -> None:
    terminal.send("stimulus(S).\n")
    assert terminal.expect(r"S = face ").endswith("\nS = face ")
    assert terminal.quiet() == ""                      # waits: no second answer yet
    terminal.send(";")
    assert terminal.expect(r"S = object ") == ";\nS = object "
    terminal.send("\r")                                # Enter: stop, as swipl
    assert terminal.expect(r"\?- ") == ".\n\n?- "
    terminal.send("between(1, inf, X).\n")             # an endless generator: one at a time
    terminal.expect(r"X = 1 ")
    terminal.send(" ")
    assert terminal.expect(r"X = 2 ") == ";\nX = 2 "
    terminal.send("c")
    terminal.expect(r"\?- ")
    terminal.send("\x04")                              # end of input leaves
    assert terminal.close() == 0


@pytest.mark.slow
def test_terminal_output_in_order_and_last_answer_without_prompt(terminal) -> None:
    terminal.send("member(X, [1, 2]), write(hello(X)), nl.\n")
    assert terminal.expect(r"X = 1 ").endswith("\nhello(1)\nX = 1 ")
    terminal.send(";")
    assert terminal.expect(r"\?- ") == ";\nhello(2)\nX = 2.\n\n?- "
    terminal.send("X = f(X).\n")
    assert terminal.expect(r"\?- ").endswith("\nX = f(X).\n\n?- ")
    terminal.send("stimulus(dog).\n")
    assert terminal.expect(r"\?- ").endswith("\nfalse.\n\n?- ")


@pytest.mark.slow
def test_terminal_write_help_and_unknown_keys(terminal) -> None:
    terminal.send("numlist(1, 12, L), member(X, [a, b]).\n")
    assert terminal.expect(r"X = a ").endswith("L = [1, 2, 3, 4, 5, 6, 7, 8, 9|...],\nX = a ")
    terminal.send("w")
    assert terminal.expect(r"X = a ") == ("[write]\nL = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, "
                                          "12],\nX = a ")
    terminal.send("h")
    assert "; (n, r, space, tab): next answer" in terminal.expect(r"X = a ")
    terminal.send("x")
    assert terminal.expect(r"Action\? ") == "\nunknown action 'x' (h for help)\nAction? "
    terminal.send(";")
    assert terminal.expect(r"\?- ").startswith(";\nL = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12],"
                                               "\nX = b.")
    terminal.send(":quit\n")
    assert terminal.close() == 0


@pytest.mark.slow
def test_terminal_time_limit_per_answer(terminal) -> None:
    terminal.send("(X = 1 ; repeat, fail).\n")
    terminal.expect(r"X = 1 ")
    time.sleep(2.5)                                    # thinking time is not query time
    terminal.send(";")
    text = terminal.expect(r"\?- ")
    assert "error: query ran longer than 2 s" in text


@pytest.mark.slow
def test_terminal_ctrl_c_stops_the_query_at_once(tmp_path: Path) -> None:
    # The limit (300 s) is far beyond the test's patience (60 s): only a Ctrl-C that stops
    # Prolog at once, as swipl's does, passes. The signal comes once the query runs.
    env = dict(os.environ, RELRL_HISTORY=str(tmp_path / "history"), TERM="dumb")
    terminal = _Terminal([sys.executable, "-m", "relrl.cli", "shell", "--timeout", "300",
                          str(FRUITS)], env)
    try:
        terminal.expect(r"\?- ")
        terminal.send("repeat, fail.\n")
        terminal.expect(r"repeat, fail\.\r?\n")     # echoed: the query was read
        time.sleep(1.0)
        terminal.proc.send_signal(signal.SIGINT)  # as Ctrl-C
        assert "% interrupted" in terminal.expect(r"\?- ", timeout=60)
        terminal.send("X = 1 ; repeat, fail.\n")   # the next answers run again
        terminal.expect(r"X = 1 ")
        terminal.send(";")
        time.sleep(1.0)
        terminal.proc.send_signal(signal.SIGINT)  # Ctrl-C while looking for answer 2
        assert "% interrupted" in terminal.expect(r"\?- ", timeout=60)
        terminal.send("stimulus(face).\n")
        assert terminal.expect(r"\?- ").endswith("\ntrue.\n\n?- ")
    finally:
        if terminal.proc.poll() is None:
            terminal.proc.kill()
            terminal.close()


# -- [user] and :learner ----------------------------------------------------------------------

def test_clauses_typed_after_user_load_as_a_file_named_user(shell, capfd) -> None:
    """``[user].`` reads the clauses that follow (to end_of_file. or the end of input) and
    loads them; it used to print "ERROR: iri_scheme `user' does not exist" first and leave
    the lines to run as queries."""
    sh, out = shell
    sh.run_lines(["[user].\n", "foo(1).\n", "foo(2).\n", "end_of_file.\n", "foo(X).\n",
                  "consult(user).\n", "foo(3).\n"])
    sh.run_lines(["foo(X).\n"])
    assert out.getvalue() == "true.\nX = 1 ;\nX = 2.\ntrue.\nX = 3.\n"
    assert sh.errors == 0 and "iri_scheme" not in capfd.readouterr().err


def test_user_clauses_with_an_error_load_nothing_and_name_the_line(shell) -> None:
    sh, out = shell
    sh.run_lines(["[user].\n", "bar(1).\n", "bar(2\n"])
    sh.run_lines(["bar(X).\n"])
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("error: user:2: Syntax error") and "(nothing loaded)" in lines[0]
    assert lines[1].startswith("error: Unknown procedure: bar/1"), lines


def test_user_without_input_is_one_error(shell) -> None:
    sh, out = shell
    sh.execute("[user].")
    assert out.getvalue() == "error: [user] reads clauses from the input, and this shell " \
                             "has none\n"


def test_a_fresh_learner_keeps_working_memory_at_its_ages() -> None:
    """``:learner NAME`` starts a run, which empties working memory: the shell puts it
    back, each element at its age (it used to leave memory empty, and :explain showed
    state 0), and says so; :help says so too."""
    from relrl import policy  # noqa: F401  (registers :learner)

    with KnowledgeBase(ROOT / "tests" / "data" / "memory_facts.pl") as kb:
        out = io.StringIO()
        sh = Shell(kb, out, timeout=5)
        sh.run_lines([":add see(s)\n", ":add see(t)\n", ":memory\n"])
        before = out.getvalue().split("inserted 1 element\n")[-1]
        code = kb.state_code()
        out.truncate(0)
        out.seek(0)
        sh.run_lines([":learner etg\n", ":memory\n", ":explain\n", ":help\n"])
        text = out.getvalue()
        assert "learner etg ready (working memory kept: 2 elements; the necessity units " \
               "start afresh)" in text
        assert before and before in text
        assert f"state {code} " in text and code != 0
        assert "working memory is kept" in text.split(":learner NAME")[1].splitlines()[0]
