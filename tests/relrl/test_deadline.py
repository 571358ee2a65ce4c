"""The time limit of a call, as call_with_time_limit/2 has it: armed while an answer is
sought, gone when the call ends — whatever way it ends — so that it never strikes a later
call; and Ctrl-C, which stops the running goal at once."""

from __future__ import annotations

import io
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator

import pytest

from relrl.errors import PrologError, QueryTimeout
from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent
from relrl.shell import Shell
from tests.conftest import FRUITS, SIS

LIMIT = 0.3


@pytest.fixture
def kb() -> Iterator[KnowledgeBase]:
    with KnowledgeBase(FRUITS, timeout=LIMIT) as kb:
        yield kb


def _later_calls_run(kb: KnowledgeBase) -> None:
    """Past the limit of whatever ran before, calls that take a while still succeed."""
    time.sleep(2 * LIMIT)
    for _ in range(3):
        assert kb.holds(("between", 1, 100_000, 100_000))
        assert kb.query("between(1, 3, X)")[0][2][0][1] == 3


@pytest.mark.slow
def test_shell_query_that_ends_with_false_leaves_no_limit_behind() -> None:
    """Regression: in relrl shell, `(X = 1 ; fail).`, `;` (false.), then a wait past the
    limit: the next query failed with time_limit_exceeded (the alarm of the exhausted
    query was still armed)."""
    with KnowledgeBase(FRUITS) as kb:
        out = io.StringIO()
        keys = iter(";")
        sh = Shell(kb, out, timeout=LIMIT, keys=lambda: next(keys, "\r"))
        sh.interactive = True
        sh.execute("(X = 1 ; fail).")
        time.sleep(2 * LIMIT)
        sh.execute("true.")
        sh.execute("between(1, 100000, 100000).")
        assert out.getvalue() == "X = 1 ;\nfalse.\n\ntrue.\n\ntrue.\n\n"
        assert sh.errors == 0


@pytest.mark.parametrize("ending", ["answer", "false", "error", "time limit"])
@pytest.mark.slow
def test_a_call_leaves_no_limit_behind(kb: KnowledgeBase, ending: str) -> None:
    if ending == "answer":
        assert kb.holds("true")
    elif ending == "false":
        assert not kb.holds("fail")
    elif ending == "error":
        with pytest.raises(PrologError):
            kb.holds(("atom_length", 1, "a"))
    else:
        with pytest.raises(QueryTimeout):
            kb.holds((",", "repeat", "fail"))
    _later_calls_run(kb)


@pytest.mark.parametrize("ending", ["closed after one answer", "exhausted", "error",
                                    "time limit"])
@pytest.mark.slow
def test_an_open_query_leaves_no_limit_behind(kb: KnowledgeBase, ending: str) -> None:
    text = {"closed after one answer": "between(1, inf, X)", "exhausted": "(X = 1 ; fail)",
            "error": "(X = 1 ; atom_length(_, _))", "time limit": "(X = 1 ; repeat, fail)"}
    with kb.open_query(text[ending]) as q:
        assert q.next().text == "X = 1"
        time.sleep(2 * LIMIT)           # thinking time between answers is not query time
        if ending == "exhausted":
            assert q.next() is None
        elif ending == "error":
            with pytest.raises(PrologError):
                q.next()
        elif ending == "time limit":
            with pytest.raises(QueryTimeout):
                q.next()
    _later_calls_run(kb)


@pytest.mark.slow
def test_a_step_leaves_no_limit_behind() -> None:
    with KnowledgeBase(SIS, timeout=LIMIT) as kb:
        agent = Agent(kb, make_learner("etg"), seed=0)
        for _ in range(3):
            agent.step([("see", "face")])
            time.sleep(2 * LIMIT)
        _later_calls_run(kb)


@pytest.mark.slow
def test_a_limit_stops_a_blocking_system_call(kb: KnowledgeBase) -> None:
    """sleep/1 waits in the OS: the limit stops it there (SWI-Prolog's alert signal)."""
    t = time.monotonic()
    with pytest.raises(QueryTimeout):
        kb.holds(("sleep", 20))
    assert time.monotonic() - t < 5
    _later_calls_run(kb)


def _sigint_after(seconds: float) -> threading.Timer:
    timer = threading.Timer(seconds, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def _quiet_sigint(test: Callable[[list], None]) -> None:
    """Run ``test`` with Python's own SIGINT handler only noting the signal (the gateway
    raises the KeyboardInterrupt of an interrupted call itself)."""
    seen: list = []
    old = signal.signal(signal.SIGINT, lambda *_: seen.append(1))
    try:
        test(seen)
    finally:
        signal.signal(signal.SIGINT, old)


@pytest.mark.slow
def test_ctrl_c_stops_the_running_goal_at_once() -> None:
    with KnowledgeBase(FRUITS, timeout=120) as kb:
        def test(seen: list) -> None:
            timer = _sigint_after(0.5)
            t = time.monotonic()
            with pytest.raises(KeyboardInterrupt), kb.interruptible():
                kb.holds((",", "repeat", "fail"))
            timer.join()
            assert time.monotonic() - t < 10 and seen
            with kb.open_query("(X = 1 ; repeat, fail)") as q, kb.interruptible():
                assert q.next().text == "X = 1"
                timer = _sigint_after(0.5)
                with pytest.raises(KeyboardInterrupt):
                    q.next()
                timer.join()
            time.sleep(0.3)
            assert kb.holds(("between", 1, 100_000, 100_000))

        _quiet_sigint(test)


def test_ctrl_c_between_calls_stops_nothing_later() -> None:
    with KnowledgeBase(FRUITS, timeout=LIMIT) as kb:
        def test(seen: list) -> None:
            with kb.interruptible():
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.3)
                assert seen
                assert kb.holds(("between", 1, 100_000, 100_000))

        _quiet_sigint(test)
