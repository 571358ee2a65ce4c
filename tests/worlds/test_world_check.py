"""``relrl check --world`` says what is wrong, once; ``relrl learn`` refuses it in one line."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from relrl.cli import main

#: a world whose goal, at(3), three go moves reach (line 8 onwards is free for a case).
BASE = """initial_state(_, [at(0)]).
task(reach).
action(go(_)).
precondition(go(X), S) :- memberchk(at(Y), S), Y < 3, X is Y + 1.
effect(go(X), S, [at(Y)], [at(X)]) :- memberchk(at(Y), S).
goal(reach, S) :- memberchk(at(3), S).
relation(at(_)).
"""


def _world(tmp_path: Path, text: str, name: str = "w.pl") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _check(path: Path, capsys) -> tuple[int, list[str]]:
    code = main(["check", "--world", str(path), "-q"])
    return code, capsys.readouterr().err.strip().splitlines()


def _learn(path: Path, capsys, *flags: str) -> tuple[int, str, str]:
    code = main(["learn", str(path), "--episodes", "10", "--no-speed", "--eval-episodes", "2",
                 "--eval-sizes", "3", *flags])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_base_world_is_valid(tmp_path: Path, capsys) -> None:
    assert _check(_world(tmp_path, BASE), capsys) == (0, [])


def test_check_world_library_predicates_count_as_defined(tmp_path: Path, capsys) -> None:
    """A world may call autoloadable library predicates; a predicate defined nowhere is
    still an error."""
    text = BASE + ("ok(S) :- vertices_edges_to_ugraph([a], [], _), empty_heap(_), "
                   "last([S], S).\n")
    good = text.replace("memberchk(at(3), S).", "memberchk(at(3), S), ok(S).")
    assert _check(_world(tmp_path, good), capsys) == (0, [])
    bad = text.replace("memberchk(at(3), S).", "memberchk(at(3), S), nowhere(S).")
    code, err = _check(_world(tmp_path, bad, "bad.pl"), capsys)
    assert code == 2 and any("goal/2 calls undefined predicate nowhere/1" in e for e in err), err


def test_check_world_unreachable_goal_is_an_error(tmp_path: Path, capsys) -> None:
    path = _world(tmp_path, BASE.replace("memberchk(at(3), S).", "memberchk(at(5), S)."))
    code, lines = _check(path, capsys)
    assert code == 2 and lines[-1] == "1 problem"
    assert lines[0].startswith(f"{path}:2: task reach: the goal reach is unreachable from the "
                               "drawn start state [at(0)]")
    code, _, err = _learn(path, capsys)
    assert code == 2 and "unreachable" in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_check_world_search_stopped_by_its_limit_is_a_warning(tmp_path: Path, capsys) -> None:
    path = _world(tmp_path, BASE.replace("Y < 3, ", "").replace("memberchk(at(3), S).",
                                                               "memberchk(at(-1), S)."))
    code, lines = _check(path, capsys)
    assert code == 0 and len(lines) == 1
    assert lines[0].startswith(f"{path}:2: warning: task reach: a breadth-first search "
                               "stopped at its limit of 20,000 states")


def test_check_world_never_bound_action_is_a_warning(tmp_path: Path, capsys) -> None:
    lines = BASE.splitlines(keepends=True)
    path = _world(tmp_path, "".join([
        *lines[:3], "action(jump(_)).\n", lines[3],
        "precondition(jump(X), S) :- memberchk(at(99), S), X = 1.\n", lines[4],
        "effect(jump(X), S, [at(Y)], [at(X)]) :- memberchk(at(Y), S).\n", *lines[5:]]))
    code, lines = _check(path, capsys)
    assert code == 0
    assert lines == [f"{path}:4: warning: action(jump(_)): precondition/2 bound this template "
                     "in no state of the checked episodes (a precondition that never holds?)"]


def _tasks(n: int, goal: str) -> str:
    tasks = "".join(f"task(t({i})).\n" for i in range(n))
    return (f"initial_state(_, [at(0)]).\n{tasks}action(go(_)).\n"
            "precondition(go(1), S) :- memberchk(at(0), S).\n"
            "effect(go(X), S, [at(Y)], [at(X)]) :- memberchk(at(Y), S).\n"
            f"relation(at(_)).\n{goal}\n")


def test_check_world_2000_tasks_one_error_one_line(tmp_path: Path, capsys) -> None:
    """A goal rule that raises for every one of 2,000 tasks: one line, and the check stops."""
    path = _world(tmp_path, _tasks(2000, "goal(t(_), S) :- atom_length(S, _)."))
    code, lines = _check(path, capsys)
    assert code == 2 and lines[-1] == "1 problem" and len(lines) == 2
    assert lines[0].startswith(f"{path}:2006: goal(t(0),[at(0)]) raised: atom_length/2: ")


def test_check_world_2000_unreachable_tasks_stop_after_ten(tmp_path: Path, capsys) -> None:
    path = _world(tmp_path, _tasks(2000, "goal(t(_), S) :- memberchk(at(5), S)."))
    code, lines = _check(path, capsys)
    assert code == 2 and lines[-1] == "10 problems" and len(lines) == 12
    assert lines[0] == (f"{path}: warning: the check stopped after 10 problems and warnings: "
                        "fix them and check again")


@pytest.mark.slow
def test_check_world_deep_recursion_reported_once(tmp_path: Path, capsys) -> None:
    """A goal rule without end: one line naming it, after one overflow (not one per
    episode and task)."""
    path = _world(tmp_path, _tasks(3, "goal(t(_), S) :- deep(S).\n"
                                      "deep(S) :- deep([x|S]), true."))
    t0 = time.monotonic()
    code, lines = _check(path, capsys)
    assert code == 2 and lines == [f"{path}:9: goal(t(0),[at(0)]) ran out of stack (a "
                                   "recursion without end?)", "1 problem"]
    assert time.monotonic() - t0 < 120


@pytest.mark.parametrize("reward, shown", [
    ("R is nan", "1.5NaN"), ("R is inf", "1.0Inf"), ("R is 10^400", "an integer of 401 digits"),
    ("R = 2000000", "2000000")])
def test_reward_not_finite_is_an_error(tmp_path: Path, capsys, reward: str, shown: str) -> None:
    path = _world(tmp_path, BASE + f"reward(_, _, _, _, R) :- {reward}.\n")
    message = (f"reward/5 gave {shown} for the action go(1): a reward must be a finite "
               "number of magnitude at most 1e+06")
    code, lines = _check(path, capsys)
    assert code == 2 and lines == [f"{path}:8: {message}", "1 problem"]
    code, _, err = _learn(path, capsys)
    assert code == 2 and err.strip().splitlines() == [
        f"relrl learn: {path}:8: {message} (relrl check --world {path})"]


@pytest.mark.parametrize("bound", ["foo", "-5", "0", "2.5"])
def test_step_bound_not_a_positive_integer_is_an_error(tmp_path: Path, capsys,
                                                       bound: str) -> None:
    path = _world(tmp_path, BASE + f"step_bound(_, _, {bound}).\n")
    message = f"step_bound/3 gave {bound} for reach: it must give a positive integer"
    code, lines = _check(path, capsys)
    assert code == 2 and lines == [f"{path}:8: {message}", "1 problem"]
    code, _, err = _learn(path, capsys)
    assert code == 2 and err.strip().splitlines() == [
        f"relrl learn: {path}:8: {message} (relrl check --world {path})"]


def test_learn_scores_no_optimum_for_an_unreachable_goal(tmp_path: Path, capsys) -> None:
    """The goal is reachable at size 3 (the check's) and unreachable at 4: relrl learn
    reports no optimum and no 0 of optimal there, and says why."""
    path = _world(tmp_path, """initial_state(N, [at(0), size(N)]).
task(reach).
action(go(_)).
precondition(go(1), S) :- memberchk(at(0), S), memberchk(size(N), S), N < 4.
effect(go(X), S, [at(Y)], [at(X)]) :- memberchk(at(Y), S).
goal(reach, S) :- memberchk(at(1), S).
relation(at(_)).
relation(size(_)).
""")
    out = tmp_path / "run"
    code, text, _ = _learn(path, capsys, "--sizes", "3", "--eval-sizes", "3,4", "--out",
                           str(out))
    assert code == 0
    assert ("size   4: of optimal -, reached 0.000, steps 0.00 (optimal -)  (2 episodes with "
            "an unreachable goal: no optimum)") in text
    test = json.loads((out / "results.json").read_text())["test"]
    assert test["4"]["optimality"] is None and test["4"]["unreachable"] == 2
    assert test["3"]["optimality"] == 1.0 and test["3"]["unreachable"] == 0
