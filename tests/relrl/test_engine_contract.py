"""The engine's contract (issue 13): bounded rules, isolated agents, one typed front,
policies read as data."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest

from relrl.bridge.calls import prolog
from relrl.engine import Engine, StepResult
from relrl.errors import (
    PolicyError,
    PrologError,
    PrologLoadError,
    QueryTimeout,
    RelrlError,
    RuleError,
)
from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent, Interaction
from relrl.sim.caregiver import make_caregiver
from relrl.sim.sis import SharedAttentionEnv
from relrl.terms import Var
from tests.conftest import ROOT

SIS = ROOT / "examples" / "domains" / "sis.pl"
TINY = ROOT / "tests" / "data" / "tiny.pl"
GATEWAY = ROOT / "prolog" / "gateway.pl"


def domain(tmp_path: Path, text: str, name: str = "d.pl") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


BASE = "stimulus(face).\nresponse(look(a)).\nresponse(look(b)).\n"


# -- 1. rules are bounded, and their errors name them --------------------------------------

@pytest.mark.slow
def test_runaway_test_raises_every_time_and_names_the_rule(tmp_path: Path) -> None:
    path = domain(tmp_path, BASE + "spin :- spin.\netg_test(spin).\n")
    with KnowledgeBase(path, timeout=0.5) as kb:
        agent = Agent(kb, make_learner("etg"), seed=0)
        for _ in range(2):  # found every step, not swallowed once and then forever slow
            with pytest.raises(QueryTimeout) as info:
                agent.step([("see", "face")])
            assert info.value.rule == "spin"
            assert info.value.where.endswith("d.pl:4")
            assert "d.pl:4: rule spin ran longer than 0.5 s" in str(info.value)


@pytest.mark.slow
def test_runaway_constraint_rule_names_the_rule(tmp_path: Path) -> None:
    path = domain(tmp_path, BASE + "forbidden(look(a)) :- repeat, fail.\n")
    with KnowledgeBase(path, timeout=0.5) as kb:
        agent = Agent(kb, make_learner("qlearning"), seed=0)
        with pytest.raises(QueryTimeout, match=r"rule forbidden\(look\(a\)\)"):
            agent.step([("see", "face")])


@pytest.mark.slow
def test_resource_error_in_a_rule_is_a_user_error_naming_it(tmp_path: Path) -> None:
    path = domain(tmp_path, BASE + "forbidden(look(b)) :- down(0).\n"
                            "down(N) :- M is N + 1, down(M), M > 0.\n")
    with KnowledgeBase(path, timeout=30) as kb:
        agent = Agent(kb, make_learner("contingency"), seed=0)
        with pytest.raises(RuleError, match=r"d\.pl:4: rule forbidden\(look\(b\)\) ran out "
                                            r"of stack"):
            agent.step([("see", "face")])
        assert kb.holds("true")  # the engine is still usable


def test_undefined_predicate_in_a_fact_is_an_error_not_false(tmp_path: Path) -> None:
    path = domain(tmp_path, BASE + "fact(broken(face)).\nbroken(face) :- nothere.\n")
    with KnowledgeBase(path, strict=False) as kb:
        agent = Agent(kb, make_learner("etg"), seed=0)
        with pytest.raises(RuleError, match=r"rule broken\(face\).*nothere/0"):
            agent.step([("see", "face")])


@pytest.mark.slow
def test_loading_runs_under_the_time_limit(tmp_path: Path) -> None:
    path = domain(tmp_path, "stimulus(face).\n:- repeat, fail.\nresponse(look).\n")
    with pytest.raises(PrologLoadError, match=r"d\.pl:2: loading ran longer than the time "
                                              r"limit") as info:
        KnowledgeBase(path, timeout=0.5)
    assert info.value.line == 2


@pytest.mark.parametrize("directive", ["halt", "halt(3)", "system:halt"])
def test_halt_in_a_loaded_file_cannot_end_relrl(tmp_path: Path, directive: str) -> None:
    path = domain(tmp_path, f"stimulus(face).\n:- {directive}.\nresponse(look).\n")
    with pytest.raises(PrologLoadError, match=r"d\.pl:2: halt/0,1 called while loading"):
        KnowledgeBase(path)
    with KnowledgeBase(SIS) as kb:  # still alive
        assert kb.holds("true")


def test_halt_in_a_rule_is_an_error(tmp_path: Path) -> None:
    path = domain(tmp_path, BASE + "fact(leave(face)).\nleave(face) :- halt.\n")
    with KnowledgeBase(path) as kb:
        agent = Agent(kb, make_learner("etg"), seed=0)
        with pytest.raises(RuleError, match=r"d\.pl:5: rule leave\(face\) called halt/0,1"):
            agent.step([("see", "face")])
        assert kb.holds("true")


@pytest.mark.parametrize("goal", ["halt", "halt(3)", "system:halt", "call(halt)"])
def test_halt_called_many_times_never_ends_relrl(tmp_path: Path, goal: str) -> None:
    """SWI-Prolog honours a cancelled halt only nine times in a process: a rule that calls
    halt/0,1 over and over (a world's precondition in every step of a check) must still
    not end relrl, and each call is an error. (In a process of its own: the halt it guards
    against would end the test run with status 0.)"""
    import subprocess
    import sys

    path = domain(tmp_path, BASE + f"fact(leave(face)).\nleave(face) :- {goal}.\n"
                  "many :- forall(between(1, 30, _), ignore(catch(leave(face), _, true))).\n")
    script = ("import sys\nfrom relrl.errors import RuleError\nfrom relrl.kb import "
              "KnowledgeBase\nwith KnowledgeBase(sys.argv[1]) as kb:\n"
              "    for _ in range(12):\n        try:\n            kb.holds('many')\n"
              "        except RuleError as exc:\n            print(exc)\n"
              "    print('alive', kb.holds('true'))\n")
    proc = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True,
                          text=True, timeout=120, cwd=ROOT)
    lines = proc.stdout.splitlines()
    assert proc.returncode == 0 and lines[-1] == "alive True", (proc.stdout, proc.stderr)
    assert len(lines) == 13 and all("halt/0,1" in line for line in lines[:-1])


def test_abort_while_loading_is_a_load_error(tmp_path: Path) -> None:
    path = domain(tmp_path, "stimulus(face).\n:- abort.\nresponse(look).\n")
    with pytest.raises(PrologLoadError, match="abort/0 called while loading"):
        KnowledgeBase(path)
    with KnowledgeBase(SIS) as kb:
        assert kb.holds("true")


@pytest.mark.slow
def test_abort_in_a_goal_or_a_step_leaves_no_deadline_behind(tmp_path: Path) -> None:
    """abort/0 unwinds past the gateway's catch/3: the call's flags and deadline are put
    back all the same, so later calls run under their own limits."""
    import time

    path = domain(tmp_path, BASE + "fact(stop(face)).\nstop(face) :- percept(hear(stop)), "
                                   "abort.\nslow :- sleep(0.1).\n")
    with KnowledgeBase(path, timeout=0.2) as kb:
        agent = Agent(kb, make_learner("etg"), seed=0)
        with pytest.raises(RuleError, match="abort/0 called"):
            kb.holds("abort")
        time.sleep(0.25)
        assert kb.holds("slow")          # the aborted call's deadline would stop it at once
        with pytest.raises(RuleError, match="abort/0 called"):
            agent.step([("see", "face"), ("hear", "stop")])
        time.sleep(0.25)
        assert kb.holds("slow")
        assert agent.step([("see", "face")]).action is not None


def test_deep_and_cyclic_terms(tmp_path: Path) -> None:
    path = domain(tmp_path, BASE + "cyc(X) :- X = f(X).\n"
                                   "deep(0, z) :- !.\ndeep(N, f(T)) :- M is N-1, deep(M, T).\n")
    with KnowledgeBase(path) as kb:
        with pytest.raises(PrologError, match="nested deeper"):
            kb.call("cyc", Var())
        with pytest.raises(PrologError, match="nested deeper"):
            kb.call("deep", 100_000, Var())
        assert kb.call("deep", 3, Var())[0] == ("f", ("f", ("f", "z")))


# -- 2. each agent owns its random stream ----------------------------------------------------

def _trajectory(learner: str, with_other: bool, steps: int = 300) -> list:
    kb = KnowledgeBase(SIS)
    agent = Agent(kb, make_learner(learner), seed=3)
    env = SharedAttentionEnv(make_caregiver("paper"), max_steps=None, record_trace=False)
    me = Interaction(env, agent)
    me.reset(seed=3)
    other = None
    if with_other:
        kb2 = KnowledgeBase(SIS)
        env2 = SharedAttentionEnv(make_caregiver("paper"), max_steps=None, record_trace=False)
        other = Interaction(env2, Agent(kb2, make_learner(learner), seed=99))
        other.reset(seed=99)
    actions = []
    for _ in range(steps):
        actions += [r.out.action for r in me.run(1)]
        if other is not None:
            other.run(1)
    kb.close()
    if other is not None:
        other.agent.kb.close()
    return actions


@pytest.mark.parametrize("learner", ["etg", "contingency", "qlearning"])
@pytest.mark.slow
def test_two_agents_in_one_process_are_isolated(learner: str) -> None:
    assert _trajectory(learner, with_other=False) == _trajectory(learner, with_other=True)


def _learning_with(between: Callable[[KnowledgeBase, int], None] | None,
                   steps: int = 200) -> list:
    """An ETG agent's actions on SIS, ``between(kb, i)`` called after each step."""
    with KnowledgeBase(SIS) as kb:
        agent = Agent(kb, make_learner("etg"), seed=4)
        env = SharedAttentionEnv(make_caregiver("paper"), max_steps=None, record_trace=False)
        me = Interaction(env, agent)
        me.reset(seed=4)
        actions = []
        for i in range(steps):
            actions += [r.out.action for r in me.run(1)]
            if between is not None:
                between(kb, i)
        return actions


@pytest.mark.slow
def test_user_queries_between_steps_leave_the_trajectory() -> None:
    """Numbers a user's query draws (a query, a call, the shell's open query, even with
    another agent's step between two of its answers) come from no agent's stream."""
    drawn: list = []
    with KnowledgeBase(SIS) as kb2:
        other = Interaction(SharedAttentionEnv(make_caregiver("paper"), max_steps=None,
                                               record_trace=False),
                            Agent(kb2, make_learner("etg"), seed=5))
        other.reset(seed=5)

        def queries(kb: KnowledgeBase, i: int) -> None:
            if i % 3 == 0:
                drawn.append(kb.query("X is random_float, Y is random(1000)")[0][0][0][1])
            elif i % 3 == 1:
                drawn.append(kb.call("random_between", 1, 1000, Var())[0])
            else:
                with kb.open_query("between(1, 2, _), X is random(1000)") as q:
                    drawn.append(q.next().text)
                    other.run(1)
                    drawn.append(q.next().text)

        alone = _learning_with(None)
        assert _learning_with(queries) == alone
    assert len(set(drawn)) > len(drawn) // 2        # the queries did draw numbers


def test_preserved_leaves_learning_as_it_was() -> None:
    def learn(evaluate: bool) -> list:
        with KnowledgeBase(SIS) as kb:
            agent = Agent(kb, make_learner("etg"), seed=1)
            env = SharedAttentionEnv(make_caregiver("paper"), max_steps=None,
                                     record_trace=False)
            learning = Interaction(env, agent)
            learning.reset(seed=1)
            actions = [r.out.action for r in learning.run(150)]
            if evaluate:
                with agent.preserved():
                    probe = Interaction(SharedAttentionEnv(make_caregiver("paper")), agent)
                    probe.reset(seed=7)
                    probe.run(80, learning=False, explore=True)
            return actions + [r.out.action for r in learning.run(150)]
    assert learn(False) == learn(True)


# -- 3. one typed front ---------------------------------------------------------------------

def test_python_calls_only_the_declared_api_and_all_of_it() -> None:
    """Python names its goals of relrl's Prolog by python_api/2's short names, asked at
    start: every name it uses is declared, and every declared name is used."""
    declared = {str(t[1]) for t in prolog().run(
        (":", "relrl_gateway", ("gw_api", Var())), 0, (0,))[0]}  # type: ignore[index]
    calls = re.compile(r'(?:\b(?:call|one|call_semidet|engine_call)\(\s*[\w.]+,\s*'
                       r'|\.goal\(|\.api(?:_det|_goal)?\(|\blayer_api\(|\._ask\()"(\w+)"')
    used = {m.group(1) for path in (ROOT / "relrl").rglob("*.py")
            for m in calls.finditer(path.read_text())}
    assert used <= declared, used - declared
    assert declared - used == {"api"}, declared - used
    for name in declared:
        prolog().goal(name)
    with pytest.raises(RelrlError, match="no goal 'nope'"):
        prolog().goal("nope")


def test_private_predicates_are_refused() -> None:
    with KnowledgeBase(TINY) as kb:
        Agent(kb, make_learner("etg"), seed=0)
        with pytest.raises(PrologError, match="private_predicate"):
            kb.call("relrl_qtree:qtree_node", kb.module, Var(), Var())
        with pytest.raises(PrologError, match="private_predicate"):
            kb.call("user:shell", "true")


def test_step_result_is_decoded() -> None:
    with KnowledgeBase(TINY) as kb:
        engine = Engine(kb)
        engine.configure("etg", {**make_learner("etg").params}, seed=0)
        r = engine.step([("see", "light"), ("smell", "food")], want=("memory", "memory_size",
                                                                      "explain"))
        assert isinstance(r, StepResult)
        assert r.code == 1 | 4 and r.necessity == "hunger" and r.reinforced
        assert r.allowed_index == [0, 1, 2] and 0 <= r.action_index <= 2
        assert r.memory_size == 2 and r.memory == ((0, ("see", "light")), (0, ("smell", "food")))
        assert r.explanation[0] == "explanation" and r.explanation[1] == "etg"


def test_a_response_called_none_is_a_response(tmp_path: Path) -> None:
    path = domain(tmp_path, "stimulus(s).\nresponse(none).\n")
    with KnowledgeBase(path) as kb:
        agent = Agent(kb, make_learner("etg"), seed=0)
        out = agent.step([("see", "s")])
        assert out.action == "none" and out.action is not None
        out = agent.step([("see", "s")])
        assert kb.memory()[0] == (0, ("emitted", "none"))


def test_traced_step_is_one_gateway_call() -> None:
    from relrl.kb import gateway_calls

    with KnowledgeBase(SIS) as kb:
        agent = Agent(kb, make_learner("etg"), seed=0)
        env = SharedAttentionEnv(make_caregiver("paper"))
        _, info = env.reset(seed=0)
        before = gateway_calls()
        for _ in range(50):
            out = agent.step(info["percepts"], want=("memory_size", "explain"))
            _, _, _, _, info = env.step(out.action)
            assert out.explanation["learner"] == "etg" and out.memory_size > 0
        assert gateway_calls() - before == 50


# -- policies are data ----------------------------------------------------------------------

def _etg_policy(tmp_path: Path) -> tuple[KnowledgeBase, Agent, Path]:
    kb = KnowledgeBase(TINY)
    agent = Agent(kb, make_learner("etg"), seed=0)
    for percepts in ([("see", "light")], [("see", "dark")], [("see", "light")]):
        agent.step(percepts)
    return kb, agent, agent.learner.save(tmp_path / "p.pl")


def test_a_directive_in_a_policy_is_refused_and_never_runs(tmp_path: Path) -> None:
    kb, agent, path = _etg_policy(tmp_path)
    marker = tmp_path / "ran"
    text = path.read_text()
    path.write_text(text + f":- shell('touch {marker}').\n")
    line = len(text.splitlines()) + 1
    with pytest.raises(PolicyError, match=rf"p\.pl:{line}: a directive in a policy file is "
                                          "refused"):
        agent.learner.load(path)
    assert not marker.exists()
    kb.close()


@pytest.mark.parametrize("extra,message", [
    ("evil(X) :- shell(X).", r"p\.pl:{line}: evil/1 is not part of a etg policy \(refused\)"),
    ("etg_node({n}, leaf(abc, [])).", r"p\.pl:{line}: leaf {n}: its state abc is not a state"),
    ("etg_node({n}, leaf(none, [e(a, high, hunger)])).",
     r"p\.pl:{line}: leaf {n}: the Q of a high is not a number"),
    ("etg_node({n}, leaf(none, [e(halt, 1.0, hunger)])).",
     r"p\.pl:{line}: leaf {n}: halt is not a response of this domain"),
    ("etg_node({n}, leaf(none, [e(a, 1.0, thirst)])).",
     r"p\.pl:{line}: leaf {n}: thirst is not a necessity of this domain"),
    ("etg_node({n}, test(0, shell(rm), nil, nil)).",
     r"p\.pl:{line}: node {n}: test 0 is stimulus\(light\) in this domain, not shell\(rm\)"),
    ("etg_node(9, leaf(none, [])).", r"p\.pl:{line}: node id 9 is out of range: this policy "
                                     r"has {n1} nodes, ids 0 to {n}"),
])
def test_foreign_or_malformed_policy_terms_are_refused(tmp_path: Path, extra: str,
                                                       message: str) -> None:
    """Each bad term is refused with the line it is on ({n}: the next node id)."""
    kb, agent, path = _etg_policy(tmp_path)
    text = path.read_text()
    n = text.count("etg_node(")
    path.write_text(text + extra.format(n=n) + "\n")
    line = len(text.splitlines()) + 1
    with pytest.raises(PolicyError, match=message.format(line=line, n=n, n1=n + 1)):
        agent.learner.load(path)
    kb.close()


def test_random_bytes_and_other_domains_are_refused(tmp_path: Path) -> None:
    kb, agent, path = _etg_policy(tmp_path)
    junk = tmp_path / "junk.pl"
    junk.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(PolicyError, match="junk.pl"):
        agent.learner.load(junk)
    with KnowledgeBase(SIS) as other:
        stranger = Agent(other, make_learner("etg"), seed=0)
        with pytest.raises(PolicyError, match=r"learned for another domain"):
            stranger.learner.load(path)
        contingency = Agent(other, make_learner("contingency"), seed=0)
        with pytest.raises(PolicyError, match=r"learned by etg, not by contingency"):
            contingency.learner.load(path)
    kb.close()


def test_arithmetic_errors_load_the_same_before_and_after_a_save(tmp_path: Path) -> None:
    """Regression: saving a policy (portray_clause) loaded library(arithmetic), after which
    `X is foo + 1` in a domain became a load error reported as "Var:Var" — before a save it
    loaded. Now it is always a load error at its line."""
    path = domain(tmp_path, BASE + "zz(X) :- X is foo + 1.\n")
    for _ in range(2):
        with pytest.raises(PrologLoadError, match=r"d\.pl:4: Arithmetic: `foo' is not a "
                                                  r"function"):
            KnowledgeBase(path)
        kb, agent, _ = _etg_policy(tmp_path)
        kb.close()


@pytest.mark.slow
def test_query_answers_that_are_cyclic_or_deep_come_as_text() -> None:
    with KnowledgeBase(TINY) as kb:
        (answer,), _ = kb.query("X = f(X)")
        name, value, printed = answer[0]
        assert name == "X" and value == printed and printed.startswith("f(f(")
        (answer,), _ = kb.query("numlist(1, 100000, L), foldl([_, A, f(A)]>>true, L, z, T)")
        deep = {name: value for name, value, _ in answer}["T"]
        assert isinstance(deep, str) and "(...)" in deep
        (answer,), _ = kb.query("X = [1, 2, f(a)]")
        assert answer[0][1] == [1, 2, ("f", "a")]


def test_step_reads_codes_and_masks_beyond_64_bits(tmp_path: Path) -> None:
    """The step's fast read (gw_step/15) falls back to full conversion where a field does
    not fit its one-call read: a state code or a response mask beyond 64 bits."""
    n = 70
    text = "".join(f"stimulus(s{i}).\nresponse(r{i}).\n" for i in range(n))
    text += "forbidden(r0) :- fail.\n"     # a constraint rule: the engine builds the mask
    with KnowledgeBase(domain(tmp_path, text)) as kb:
        engine = Engine(kb)
        engine.configure("etg", {**make_learner("etg").params}, seed=0)
        features = kb.features()
        r = engine.step([("see", f"s{n - 1}")])
        assert r.code == 2 ** features.index(("stimulus", f"s{n - 1}")) and r.code >= 2 ** 63
        assert r.allowed_mask == 2 ** n - 1 and r.allowed_index == list(range(n))
        assert engine.responses[r.action_index] in {f"r{i}" for i in range(n)}
        assert r.necessity == "none" and r.outputs == () and not r.reinforced


def test_every_response_allowed_is_minus_one_and_read_as_all(tmp_path: Path) -> None:
    """Without constraint rules the engine reports -1 (every response allowed) instead of a
    mask of as many bits; Engine.step gives the full mask and the loop every response."""
    from relrl.engine import ALL_ALLOWED
    from relrl.loop import Agent

    n = 70
    text = "".join(f"stimulus(s{i}).\nresponse(r{i}).\n" for i in range(n))
    with KnowledgeBase(domain(tmp_path, text)) as kb:
        engine = Engine(kb)
        engine.configure("etg", {**make_learner("etg").params}, seed=0)
        assert engine.step_fields([("see", "s1")])[5] == ALL_ALLOWED
        r = engine.step([("see", "s1")])
        assert r.allowed_mask == 2 ** n - 1 and r.allowed_index == list(range(n))
        out = Agent(kb, make_learner("qlearning"), seed=0).step([("see", "s1")])
        assert out.allowed_index == list(range(n)) and len(out.allowed) == n
        assert out.action in out.allowed


def test_step_failure_and_errors_through_the_fast_read(tmp_path: Path) -> None:
    with KnowledgeBase(TINY) as kb:
        engine = Engine(kb)
        with pytest.raises(PrologError):        # not configured: an error, never a crash
            engine.step([("see", "light")])


def _closed_loop(steps: int) -> list[tuple]:
    """A seeded closed-loop ETG run on the simulator, some steps asking for extras."""
    with KnowledgeBase(SIS) as kb:
        agent = Agent(kb, make_learner("etg"), seed=3)
        env = SharedAttentionEnv(make_caregiver("paper"))
        _, info = env.reset(seed=3)
        seen = []
        for i in range(steps):
            want = ("memory", "memory_size", "explain") if i % 7 == 0 else ()
            out = agent.step(info["percepts"], want=want)
            seen.append((out.code, out.necessity, out.outputs, out.reward, out.allowed,
                         out.action, out.reinforced, out.memory, out.memory_size,
                         out.explanation))
            _, _, _, _, info = env.step(out.action)
        return seen


@pytest.mark.slow
def test_fields_the_kernel_does_not_read_come_as_terms(monkeypatch: pytest.MonkeyPatch) -> None:
    """Where the compiled step cannot read a field (here: no room for the units' outputs),
    the step's fields are read as terms from the frame it leaves open: the same results,
    with every record made anew (a table of one)."""
    import numpy as np

    from relrl.bridge import marshal, stepkernel
    from relrl.bridge.calls import prolog

    engine = prolog()
    plain = _closed_loop(300)
    k, io, fo = engine._kernel
    statuses: list[int] = []
    step = stepkernel.step

    def counted(io: np.ndarray, fo: np.ndarray) -> int:
        statuses.append(step(io, fo))
        return statuses[-1]

    monkeypatch.setattr(engine, "_kernel", (k, io, np.zeros(k.FIRST_OUTPUT, np.float64)))
    monkeypatch.setattr(k, "step", counted)
    monkeypatch.setattr(marshal, "CACHE_SIZE", 1)
    assert _closed_loop(300) == plain and set(statuses) == {k.READ_REST}
