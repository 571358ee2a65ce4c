"""The tg learner through the engine: it learns a small relational task and acts correctly,
with no further learning, on places it never saw; save -> load -> same choices; same seed
-> same trajectory; explanations with bindings; readable policies; bad biases."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from relrl.cli import main
from relrl.kb import KnowledgeBase
from relrl.learners import make_learner
from relrl.loop import Agent, run
from tests.conftest import ROOT
from tests.relrl.tasks import GazeTask

GAZE = ROOT / "tests" / "data" / "tg_gaze.pl"
TRAINED, NEW = ("p1", "p2"), ("p3", "p4")


def trained(steps: int = 800, seed: int = 3, **params: float) -> Agent:
    kb = KnowledgeBase(GAZE)
    agent = Agent(kb, make_learner("tg", min_examples=10, **params), seed=seed)
    run(GazeTask(TRAINED), agent, steps, seed=seed)
    return agent


def accuracy(agent: Agent, places: tuple[str, ...], steps: int = 200) -> float:
    records = run(GazeTask(places), agent, steps, learning=False, seed=99)
    return float(np.mean([r.info["fed"] for r in records]))


def test_learns_and_generalises_to_places_never_seen() -> None:
    agent = trained()
    assert accuracy(agent, TRAINED) == 1.0
    # p3 and p4 never appeared while learning; greedy choices, nothing learned meanwhile
    size = agent.learner.size()
    assert accuracy(agent, NEW) == 1.0
    assert agent.learner.size() == size
    # one test relates the action to the gaze: no place of its own
    assert "gaze(face, P), action(look(P))" in agent.learner.tree()
    agent.kb.close()


def test_qlearning_does_not_generalise() -> None:
    kb = KnowledgeBase(GAZE)
    agent = Agent(kb, make_learner("qlearning", epsilon=0.2), seed=3)
    run(GazeTask(TRAINED), agent, 800, seed=3)
    assert accuracy(agent, TRAINED) == 1.0
    assert accuracy(agent, NEW) < 0.5          # chance is 0.25
    kb.close()


def test_save_load_same_choices(tmp_path: Path) -> None:
    agent = trained()
    path = agent.learner.save(tmp_path / "tg.pl")
    before = [r.out.action for r in run(GazeTask(), agent, 60, learning=False, seed=7)]
    with KnowledgeBase(GAZE) as kb2:
        fresh = Agent(kb2, make_learner("tg"), seed=agent.seed)
        fresh.learner.load(path)
        after = [r.out.action for r in run(GazeTask(), fresh, 60, learning=False, seed=7)]
        assert after == before
        assert fresh.learner.tree().splitlines()[0] == agent.learner.tree().splitlines()[0]
    agent.kb.close()


@pytest.mark.slow
def test_same_seed_same_trajectory() -> None:
    def trajectory(seed: int) -> list:
        with KnowledgeBase(GAZE) as kb:
            agent = Agent(kb, make_learner("tg", min_examples=10), seed=seed)
            return [(r.out.action, r.out.reward) for r in run(GazeTask(), agent, 300, seed=seed)]
    assert trajectory(5) == trajectory(5)
    assert trajectory(5) != trajectory(6)


def test_two_agents_in_one_process_interleaved_as_alone() -> None:
    from relrl.loop import Interaction

    def alone(seed: int) -> list:
        with KnowledgeBase(GAZE) as kb:
            agent = Agent(kb, make_learner("tg", min_examples=10), seed=seed)
            return [r.out.action for r in run(GazeTask(), agent, 300, seed=seed)]

    with KnowledgeBase(GAZE) as kb1, KnowledgeBase(GAZE) as kb2:
        runs = []
        for kb, seed in ((kb1, 5), (kb2, 6)):
            it = Interaction(GazeTask(), Agent(kb, make_learner("tg", min_examples=10),
                                               seed=seed))
            it.reset(seed=seed)
            runs.append(it)
        both: list[list] = [[], []]
        for _ in range(300):                    # one step of each in turn
            for i, it in enumerate(runs):
                both[i] += [r.out.action for r in it.run(1)]
    assert both == [alone(5), alone(6)]


def test_explanation_shows_the_tests_and_bindings() -> None:
    agent = trained()
    out = agent.step([("see", "face"), ("pose", "face", "p4")], learning=False,
                     want=("explain",))
    assert out.action == ("look", "p4")
    exp = out.explanation
    assert exp["learner"] == "tg"
    assert "gaze(face,p4)" in exp["state"]
    assert exp["ranked"][0]["response"] == "look(p4)"
    assert {"test": "gaze(face, P), action(look(P))", "holds": True,
            "bindings": {"P": "p4"}} in exp["path"]
    assert exp["paths"]["look(p1)"][0]["holds"] is False
    agent.kb.close()


@pytest.mark.slow
def test_policy_reads_as_rules_and_consults_in_plain_swipl(tmp_path: Path) -> None:
    agent = trained()
    path = agent.learner.save(tmp_path / "tg.pl")
    text = path.read_text()
    assert "q(look(P), _, " in text and ":-\n    gaze(face, P)." in text
    # plain swipl: the domain, the policy; the rules answer for the state in memory
    goal = ("remember([see(face), pose(face, p3)]), q(look(p3), curiosity, Q), "
            "q(look(p1), curiosity, Q1), Q > Q1 + 50")
    proc = subprocess.run(["swipl", "--on-warning=status", "-g", goal, "-t", "halt",
                           str(ROOT / "prolog" / "relrl.pl"), str(GAZE), str(path)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    agent.kb.close()


def test_edited_policy_refused_with_file_and_line(tmp_path: Path) -> None:
    from relrl.errors import PolicyError

    agent = trained()
    path = agent.learner.save(tmp_path / "tg.pl")
    path.write_text(path.read_text() + "\nhalt_now :- halt.\n")
    with KnowledgeBase(GAZE) as kb2:
        fresh = Agent(kb2, make_learner("tg"), seed=0)
        with pytest.raises(PolicyError, match=r"tg\.pl:\d+: halt_now/0 is not part of a tg "
                                              r"policy"):
            fresh.learner.load(path)
    agent.kb.close()


@pytest.mark.parametrize("text,line,message", [
    ("response(look(a)).\nrmode(gaze(#agent, -place)).\n", 2,
     "gaze/2 is not a declared relation"),
    ("response(look(a)).\nrelation(seen(_)).\nseen(a).\nrmode(seen(#thing)).\n", 4,
     "no constants of type thing"),
    ("response(look(a)).\nrelation(seen(_)).\nseen(a).\nrmode(seen(+place)).\n", 4,
     "+place can never be bound"),
    ("response(look(a)).\nrmode(action(point(-place))).\n", 2,
     "matches no declared response"),
    ("response(look(a)).\nrelation(gaze(_, _)).\n", 2,
     "relation/1 calls undefined predicate gaze/2"),
])
def test_bad_bias_one_line_with_file_and_line(text: str, line: int, message: str,
                                              write_domain, capsys) -> None:
    path = write_domain("stimulus(face).\n" + text)
    assert main(["check", "-q", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and err[1] == "1 problem"
    assert err[0].startswith(f"{path}:{line + 1}: ") and message in err[0]


def test_check_lists_the_refinements(capsys) -> None:
    assert main(["check", str(GAZE)]) == 0
    out = capsys.readouterr().out
    assert "relations (the relational view, learner tg):\n  gaze(_, _)\n  fed(_)" in out
    assert "  gaze(face, P), action(look(P))\n" in out


def test_shell_loads_the_policy_acts_the_same_and_explains_with_bindings(tmp_path: Path) -> None:
    import io

    from relrl.policy import load_policy
    from relrl.shell import Shell

    agent = trained()
    path = agent.learner.save(tmp_path / "tg.pl")
    places = ("p1", "p2", "p3", "p4")
    expected = [agent.step([("see", "face"), ("pose", "face", p)], learning=False).action
                for p in places]
    assert expected == [("look", p) for p in places]
    with KnowledgeBase(GAZE) as kb2:
        out = io.StringIO()
        shell = Shell(kb2, out, timeout=5.0)
        load_policy(shell, path)
        shell.run_lines([f":step see(face), pose(face, {p})\n" for p in places])
        assert [line for line in out.getvalue().splitlines() if line.startswith("response")] \
            == [f"response: look({p})" for p in places]
        shell.run_lines([":explain\n"])
        assert "gaze(face, P), action(look(P)) -> yes  (P = p4)" in out.getvalue()
    agent.kb.close()


def test_graph_draws_the_tree() -> None:
    agent = trained()
    graph = agent.learner.graph()
    size = agent.learner.size()
    kinds = [n["kind"] for n in graph["nodes"]]
    assert kinds.count("test") == size["tests"] and kinds.count("leaf") == size["leaves"]
    assert len(graph["edges"]) == 2 * size["tests"]
    ids = {n["id"] for n in graph["nodes"]}
    assert all(e["from"] in ids and e["to"] in ids for e in graph["edges"])
    root = graph["nodes"][0]
    assert root == {"id": root["id"], "kind": "test", "label": "gaze(face, P), action(look(P))"}
    assert sorted(e["branch"] for e in graph["edges"] if e["from"] == root["id"]) == ["no", "yes"]
    assert all(n["label"].startswith("Q=") for n in graph["nodes"] if n["kind"] == "leaf")
    agent.kb.close()


@pytest.mark.slow
def test_example_learns_gaze_following_on_the_sis(tmp_path: Path) -> None:
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "tg_gaze_following.py"),
                           "--steps", "2000", "--policy", str(tmp_path / "tg.pl")],
                          capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert "gaze(face, P), action(look(P)) ?" in proc.stdout
    for place in ("left", "left_down", "down", "right_down", "right"):
        assert f"gaze {place:<10} -> look({place})" in proc.stdout
    assert "q(look(P), _, " in (tmp_path / "tg.pl").read_text()


@pytest.mark.parametrize("params,message", [
    ({"significance": 0.0}, "significance must be in"),
    ({"min_examples": 2}, "min_examples must be a whole number >= 3"),
    ({"min_examples": 4.5}, "min_examples must be a whole number >= 3"),
    ({"temperature": -1}, "temperature must be >= 0"),
    ({"stale_bonus": -0.5}, "stale_bonus must be >= 0"),
    ({"half_life": -10}, "half_life must be >= 0"),
    ({"novelty_bonus": -1}, "novelty_bonus must be >= 0"),
    ({"novelty_confidence": -2}, "novelty_confidence must be >= 0"),
])
def test_bad_parameters(params: dict, message: str) -> None:
    from relrl.errors import ConfigError

    with pytest.raises(ConfigError, match=message):
        make_learner("tg", **params)


def test_bad_parameter_on_the_command_line(capsys) -> None:
    assert main(["experiment", "sis", "--learners", "tg", "--param", "tg.half_life=-1",
                 "--quick", "--out", "/nonexistent/never-written"]) == 2
    assert "half_life must be >= 0" in capsys.readouterr().err


@pytest.mark.slow
def test_negations_leave_out_what_the_body_proves_and_old_policies_load(tmp_path: Path) -> None:
    """A no-branch below a test that introduced a variable is written as the negation of
    the test alone when it shares no variable with the path (the body proves the path);
    a policy written with the whole path query in the negation, as before, still loads."""
    from relrl.experiments.sis import DEFAULT_DOMAIN
    from relrl.sim.caregiver import make_caregiver
    from relrl.sim.sis import SharedAttentionEnv

    with KnowledgeBase(DEFAULT_DOMAIN) as kb:
        agent = Agent(kb, make_learner("tg"), seed=0)
        env = SharedAttentionEnv(make_caregiver("paper"), max_steps=None, record_trace=False)
        run(env, agent, 4000, seed=0)
        path = agent.learner.save(tmp_path / "tg.pl")
        text = path.read_text()
        m = re.search(r"q\(look\(P\), _, [0-9.]+\) :-\n    gaze\(face, P\),\n"
                      r"    gaze\(face, centre\),\n    \\\+ heard\(attention\)\.\n", text)
        assert m, text                          # the short form: \+ heard(attention)
        short = m.group(0)
        full = short.replace("    \\+ heard(attention).\n",
                             "    \\+ ( gaze(face, P1),\n         look(P)=look(P1),\n"
                             "         heard(attention)\n       ).\n")
        assert full != short
        old = tmp_path / "old.pl"
        old.write_text(text.replace(short, full))
        fresh_env = SharedAttentionEnv(make_caregiver("paper"), max_steps=None,
                                       record_trace=False)
        before = [r.out.action for r in run(fresh_env, agent, 200, learning=False, seed=5)]
        agent.learner.load(old)
        after = [r.out.action for r in run(fresh_env, agent, 200, learning=False, seed=5)]
        assert after == before
        wrong = tmp_path / "wrong.pl"          # a negation of something else is refused
        wrong.write_text(text.replace(short, full.replace("heard(attention)", "sees(toy)")))
        from relrl.errors import PolicyError

        with pytest.raises(PolicyError):
            agent.learner.load(wrong)
