"""Working memory survives signal handlers that run Prolog code during a step.

The experiment's evaluation keeps the engine's state (working memory included) and resumes
it after its runs. Two Experiment 1 runs died on resume with ``domain_error(
working_memory_state, wm(..., [...|_]))``: the memory kept had an unbound tail. The cause:
a signal handler (the gateway's old alarm re-arming itself) stored a term on the global
stack in the middle of an insertion; the list cells bound after that were trailed, and the
gateway's discarded frame undid them, cutting the memory, which had been linked into its
global variable rather than copied, short. Here a Prolog thread of the domain signals the
stepping thread every 50 µs with a handler that does the same; every keep/resume must
find a whole memory.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from relrl.engine import Engine
from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from tests.conftest import ROOT

pytestmark = pytest.mark.slow  # every test here takes a second or more

SIS = ROOT / "examples" / "domains" / "sis.pl"

POKER = """
:- use_module(library(lists)).
poke :- get_time(T), nb_setval(relrl_test_poke, T).
poker(Target, Queue) :-
    (   thread_get_message(Queue, stop, [timeout(0.00005)])
    ->  true
    ;   catch(thread_signal(Target, poke), error(existence_error(_, _), _), true),
        poker(Target, Queue)
    ).
start_poker :-
    thread_self(Me), message_queue_create(Q),
    thread_create(poker(Me, Q), Id, []), nb_setval(relrl_test_poker, Id-Q).
stop_poker :-
    nb_getval(relrl_test_poker, Id-Q),
    thread_send_message(Q, stop), thread_join(Id, _), message_queue_destroy(Q).
"""

PERCEPTS = [
    [("see", "face"), ("pose", "face", "frontal"), ("hear", "attention"), ("at", "centre")],
    [("see", "face"), ("pose", "face", "right_down"), ("at", "centre")],
    [("see", "face"), ("pose", "face", "left"), ("at", "left")],
]


def test_keep_and_resume_under_signals(tmp_path: Path) -> None:
    poker = tmp_path / "poker.pl"
    poker.write_text(POKER)
    with KnowledgeBase(SIS) as kb:
        kb.load(poker)
        engine = Engine(kb)
        engine.configure("contingency", make_learner("contingency").params, seed=0)
        kb.call(f"{kb.module}:start_poker")
        try:
            emitted = -1
            for i in range(6000):
                result = engine.step(PERCEPTS[i % 3], emitted)
                emitted = result.action_index
                if i % 3 == 2:            # an evaluation between training steps
                    slot = engine.keep()
                    engine.step(PERCEPTS[0], emitted, mode="greedy")
                    engine.resume(slot)
        finally:
            kb.call(f"{kb.module}:stop_poker")
