"""The gateway: loading, isolation, conversion both ways, errors, time limits."""

from __future__ import annotations

import threading

import pytest

from relrl.errors import PrologError, PrologLoadError, QueryTimeout, RelrlError
from relrl.kb import KnowledgeBase, gateway_calls
from relrl.terms import Var, format_term
from tests.conftest import FRUITS, SIS


@pytest.fixture
def fruits():
    with KnowledgeBase(FRUITS) as kb:
        yield kb


def test_declarations_enumerate(fruits: KnowledgeBase) -> None:
    assert fruits.declarations("stimulus") == ["face", "object", "attention", "environment"]
    assert len(fruits.declarations("response")) == 7
    assert fruits.declarations("necessity") == ["socialize"]
    assert len(fruits.declarations("fact")) == 11


def test_compound_terms_keep_structure(fruits: KnowledgeBase) -> None:
    (value,) = fruits.call("=", Var(), ("f", "a", [1, 2.5, "b"], ("g", -3)))
    assert value == ("f", "a", [1, 2.5, "b"], ("g", -3))


def test_values_round_trip_unicode_and_big_ints(fruits: KnowledgeBase) -> None:
    for v in ["maçã", "it's", "Apple", 2**70, -(2**63), 1e-300, [], [[]]]:
        assert fruits.call("=", Var(), v) == [v]


def test_user_text_is_data_not_code(fruits: KnowledgeBase) -> None:
    # A percept carrying hostile text is stored as an atom; nothing is run.
    evil = "x), halt, (true"
    fruits.insert([("hear", evil)])
    assert fruits.memory() == [(0, ("hear", evil))]
    assert format_term(("hear", evil)) == "hear('x), halt, (true')"


def test_state_code_and_decode(fruits: KnowledgeBase) -> None:
    fruits.insert([("see", "face"), ("pose", "face", "frontal"), ("at", "centre")])
    code = fruits.state_code()
    assert code == 2**0 + 2**7 + 2**13
    assert fruits.decode_state(code) == fruits.state_terms()
    assert ("fact", ("frontal", "face")) in fruits.decode_state(code)


def test_two_knowledge_bases_are_isolated() -> None:
    with KnowledgeBase(FRUITS) as a, KnowledgeBase(FRUITS) as b:
        a.insert([("see", "face")])
        assert b.memory() == []
        assert a.module != b.module


def test_different_domains_side_by_side() -> None:
    with KnowledgeBase(FRUITS) as a, KnowledgeBase(SIS) as b:
        assert "object" in a.declarations("stimulus")
        assert "toy" in b.declarations("stimulus")
        assert "toy" not in a.declarations("stimulus")


def test_missing_file() -> None:
    with pytest.raises(PrologLoadError, match="no such file"):
        KnowledgeBase("does/not/exist.pl")


def test_syntax_error_names_file_and_line(write_domain) -> None:
    path = write_domain("stimulus(face).\nresponse(look(left).\n")
    with pytest.raises(PrologLoadError) as err:
        KnowledgeBase(path)
    assert err.value.line == 2
    assert str(err.value).startswith(f"{path}:2: ")
    assert "Syntax error" in str(err.value)


def test_singletons_are_errors_when_strict(write_domain) -> None:
    path = write_domain("stimulus(face).\nfact(f(face)).\nf(X) :- see(Y).\n")
    with pytest.raises(PrologLoadError, match="Singleton"):
        KnowledgeBase(path)
    kb = KnowledgeBase()
    warnings = kb.load(path, strict=False)
    assert [w.line for w in warnings] == [3]
    kb.close()


def test_runaway_query_times_out(write_domain) -> None:
    path = write_domain("stimulus(face).\nloop :- loop_more.\nloop_more :- loop.\n")
    with KnowledgeBase(path, timeout=0.2) as kb:
        with pytest.raises(QueryTimeout):
            kb.holds("loop")
        # the engine is usable afterwards
        assert kb.holds(("stimulus", "face"))


def test_prolog_exception_becomes_prolog_error(fruits: KnowledgeBase) -> None:
    with pytest.raises(PrologError, match="Unknown procedure: no_such_predicate/0"):
        fruits.holds("no_such_predicate")
    with pytest.raises(PrologError) as err:
        fruits.call("atom_length", 1, "a")
    assert err.value.term[0] == "error"
    assert err.value.term[1] == ("type_error", "integer", "a")


def test_query_returns_every_solution(fruits: KnowledgeBase) -> None:
    solutions, more = fruits.query("response(look(P))")
    assert [s[0][1] for s in solutions] == ["centre", "left", "left_down", "down",
                                            "right_down", "right"]
    assert not more
    solutions, more = fruits.query("between(1, 1000, X)", max_solutions=5)
    assert len(solutions) == 5 and more


def test_query_syntax_error_is_prolog_error(fruits: KnowledgeBase) -> None:
    with pytest.raises(PrologError, match="Syntax error"):
        fruits.query("foo(")


def test_one_call_per_request(fruits: KnowledgeBase) -> None:
    before = gateway_calls()
    fruits.state_code()
    assert gateway_calls() - before == 1


def test_other_threads_are_refused(fruits: KnowledgeBase) -> None:
    errors: list[Exception] = []

    def worker() -> None:
        try:
            fruits.state_code()
        except RelrlError as exc:
            errors.append(exc)

    t = threading.Thread(target=worker)
    t.start()
    t.join()
    assert errors and "thread" in str(errors[0])


def test_close_twice(fruits: KnowledgeBase) -> None:
    fruits.close()
    fruits.close()


@pytest.mark.slow
def test_a_million_calls_do_not_exhaust_the_string_stack() -> None:
    """Regression: every call pushed a text buffer on Prolog's string stack, which only a
    returning foreign predicate pops; an experiment of ~600k steps died with 'Too many
    stacked strings' (fatal, no exception). The gateway now pops them after each call."""
    from relrl.bridge.calls import prolog

    engine = prolog()
    with KnowledgeBase() as kb:
        goal = (":", kb.module, "true")
        for _ in range(1_300_000):
            engine.run(goal, 0, ())
        assert engine.run((":", kb.module, ("=", Var(), "still alive")), 0, (0,)) == \
            ["still alive"]


def test_partial_list_keeps_its_tail(fruits: KnowledgeBase) -> None:
    """Regression: [1, 2|T] came back as [1, 2, T], a proper list of three."""
    (value,) = fruits.call("=", Var(), ("[|]", 1, ("[|]", 2, Var("T"))))
    assert value[0] == "[|]" and value[1] == 1
    assert value[2][0] == "[|]" and value[2][1] == 2 and isinstance(value[2][2], Var)


@pytest.mark.slow
def test_time_limit_holds_across_many_short_calls() -> None:
    """Calls that end in time never see the watchdog fire, however long they run
    together, and a runaway call after them is still stopped at its own limit."""
    import time

    with KnowledgeBase(SIS, timeout=0.2) as kb:
        start = time.monotonic()
        calls = 0
        while time.monotonic() - start < 1.0:    # five limits' worth of short calls
            assert kb.holds(("between", 1, 200, 200))
            calls += 1
        assert calls > 100
        t = time.monotonic()
        with pytest.raises(QueryTimeout):
            kb.holds((",", ("repeat",), ("fail",)))
        assert 0.15 < time.monotonic() - t < 1.5
        with pytest.raises(QueryTimeout):          # an inner, shorter limit holds too
            kb.holds((",", ("repeat",), ("fail",)), timeout=0.05)
        assert kb.holds(("true",))                 # and nothing fires afterwards
        time.sleep(0.3)
        assert kb.holds(("between", 1, 1000, 1000))


def test_cached_keys_are_equal_only_for_equal_terms() -> None:
    """A recorded term is found by its key: terms that Python calls equal but Prolog does
    not (1, 1.0, True; a list and a compound) must have different keys."""
    from relrl.bridge.marshal import Cached

    def key(value: object) -> object:
        return Cached(value).key

    percepts = [("see", "face"), ("at", "face", "left")]
    assert key(percepts) == key([("see", "face"), ("at", "face", "left")])
    assert key(percepts) != key(tuple(percepts)) != key([("see", "face")])
    assert len({key([("f", 1)]), key([("f", 1.0)]), key([("f", True)]),
                key([("f", "1")])}) == 4
    assert len({key([1]), key([1.0]), key([True]), key(["1"]), key([[1]]), key([(1,)]),
                key([("f", [1])]), key([("f", (1,))])}) == 8


def test_long_and_cyclic_lists_are_refused(
        write_domain, monkeypatch: pytest.MonkeyPatch) -> None:
    from relrl.bridge import marshal

    monkeypatch.setattr(marshal, "MAX_LIST", 1000)
    path = write_domain("cyclist(X) :- X = [a|X].\n")
    with KnowledgeBase(path) as kb:
        assert len(kb.call("numlist", 1, 1000, Var())[0]) == 1000
        with pytest.raises(PrologError, match="longer than 1000"):
            kb.call("numlist", 1, 1001, Var())
        with pytest.raises(PrologError, match="longer than 1000 elements \\(or cyclic\\)"):
            kb.call("cyclist", Var())


@pytest.mark.slow
def test_compiled_calls_load_with_the_first_step_only() -> None:
    """A process that only loads and queries (relrl check, a shell) never imports numba;
    the first control step loads the compiled step and reader."""
    import subprocess
    import sys

    script = (
        "import sys\n"
        "from relrl.kb import KnowledgeBase\n"
        "from relrl.learners import make_learner\n"
        "from relrl.loop import Agent\n"
        f"kb = KnowledgeBase({str(SIS)!r})\n"
        "kb.query('X = f(a, [b])')\n"
        "agent = Agent(kb, make_learner('etg'), seed=0)\n"
        "print('numba' in sys.modules)\n"
        "agent.step([('see', 'face')])\n"
        "print('numba' in sys.modules, kb.query('X = f(a, [b])')[0][0][0][1])\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=120, check=True).stdout.split("\n")
    assert out[0] == "False" and out[1] == "True ('f', 'a', ['b'])"


@pytest.mark.parametrize("module, above", [
    ("relrl.bridge.lib", {"relrl.bridge.marshal", "relrl.bridge.calls"}),
    ("relrl.bridge.marshal", {"relrl.bridge.calls"}),
    ("relrl.bridge.calls", set()),
    ("relrl.query", set()),
    ("relrl.engine", set()),
])
@pytest.mark.slow
def test_the_transport_imports_no_layer_above_it(module: str, above: set[str]) -> None:
    """Layers import only the ones below them: bindings < terms < calls < the facade (kb)
    and its typed front (engine) and user queries (query); none imports pyswip."""
    import subprocess
    import sys

    code = f"import sys, {module}; print(sorted(m for m in sys.modules if m.startswith(" \
           "('relrl.kb', 'relrl.loop', 'relrl.engine', 'relrl.query', 'relrl.bridge', 'pyswip'))))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    loaded = set(eval(out))
    upper = {"relrl.kb", "relrl.loop", "pyswip"} | above
    if module != "relrl.engine":
        upper.add("relrl.engine")
    if module != "relrl.query":
        upper.add("relrl.query")
    assert not loaded & upper, f"import {module} imported {sorted(loaded & upper)}"
