"""``relrl evaluate``: a saved policy acts, with no learning, from hand-made or drawn states."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from relrl.bridge.calls import display_path
from relrl.cli import main
from relrl.worlds import World

ROOT = Path(__file__).resolve().parents[2]
BLOCKS = ROOT / "examples" / "worlds" / "blocks.pl"

#: hand-made stack states with known optima: two blocks on the floor (1 move), three on
#: the floor (2), b1 on b2 beside b3 (1), already one tower (0).
STACK_STATES = """% hand-made start states
[on(b1, floor), on(b2, floor), clear(b1), clear(b2)].
state([on(b1, floor), on(b2, floor), on(b3, floor), clear(b1), clear(b2), clear(b3)]).

[on(b1, b2), on(b2, floor), on(b3, floor), clear(b1), clear(b3)].
[on(b1, b2), on(b2, floor), clear(b1)].
"""


@pytest.fixture(scope="module")
def policies(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A tg policy of stack learned to optimal on 3 blocks, and one of on(A, B)."""
    folder = tmp_path_factory.mktemp("policies")
    out = {}
    for task, episodes in (("stack", 150), ("on", 20)):
        with World(BLOCKS) as world:
            world.attach(world.learner("tg"), seed=0, task=task)
            world.episodes(task, [3], episodes, "learn")
            out[task] = world.save_policy(folder / f"{task}.pl", f"test policy: {task}")
    return out


def _evaluate(policy: Path, task: str, *flags: str) -> int:
    return main(["evaluate", str(policy), "--world", str(BLOCKS), "--task", task, *flags])


def test_evaluate_prolog_states_with_known_optima(policies, tmp_path: Path, capsys) -> None:
    states = tmp_path / "states.pl"
    states.write_text(STACK_STATES)
    out = tmp_path / "out"
    assert _evaluate(policies["stack"], "stack", "--states", str(states), "--out", str(out),
                     "--actions") == 0
    rows = list(csv.DictReader((out / "episodes.csv").open()))
    assert [r["optimal"] for r in rows] == ["1", "2", "1", "0"]
    assert [r["where"].rsplit(":", 1) for r in rows] == [[display_path(str(states)), n]
                                                         for n in ("2", "3", "5", "6")]
    assert all(r["reached"] == "True" for r in rows)
    assert [r["steps"] for r in rows] == ["1", "2", "1", "0"]     # the policy is optimal
    result = json.loads((out / "results.json").read_text())
    assert result["summary"]["states"]["optimality"] == 1.0
    assert result["rows"][0]["actions"] in (["move(b1,b2)"], ["move(b2,b1)"])
    assert result["rows"][3]["actions"] == []
    assert "of optimal 1.000, reached 1.000, 4 episodes" in capsys.readouterr().out


def test_evaluate_json_states_with_a_task_instance(policies, tmp_path: Path) -> None:
    """on(b1, b2) from b2 on b1: two moves (b2 to the floor, b1 onto b2); from b1 and b2 on
    the floor: one."""
    states = tmp_path / "states.json"
    states.write_text(json.dumps([
        {"state": ["on(b2, b1)", "on(b1, floor)", "clear(b2)"], "task": "on(b1, b2)"},
        {"state": ["on(b1, floor)", "on(b2, floor)", "clear(b1)", "clear(b2)"],
         "task": "on(b1, b2)"}]))
    out = tmp_path / "out"
    assert _evaluate(policies["on"], "on", "--states", str(states), "--out", str(out)) == 0
    rows = json.loads((out / "results.json").read_text())["rows"]
    assert [(r["goal"], r["optimal"]) for r in rows] == [("on(b1,b2)", 2), ("on(b1,b2)", 1)]
    assert [r["where"] for r in rows] == [f"{display_path(str(states))}: state {i}"
                                          for i in (1, 2)]


def test_evaluate_sizes_from_the_worlds_initial_states(policies, tmp_path: Path,
                                                      capsys) -> None:
    out = tmp_path / "out"
    assert _evaluate(policies["stack"], "stack", "--sizes", "4,6", "--episodes", "3",
                     "--out", str(out)) == 0
    text = capsys.readouterr().out
    assert "size   4: of optimal" in text and "size   6: of optimal" in text
    result = json.loads((out / "results.json").read_text())
    assert [r["size"] for r in result["rows"]] == [4, 4, 4, 6, 6, 6]
    assert all(r["optimal"] is not None for r in result["rows"])
    # the same seed, the same episodes
    again = tmp_path / "again"
    assert _evaluate(policies["stack"], "stack", "--sizes", "4,6", "--episodes", "3",
                     "--out", str(again)) == 0
    assert (again / "episodes.csv").read_text() == (out / "episodes.csv").read_text()


@pytest.mark.parametrize("name, text, message", [
    ("syntax.pl", "[on(b1, floor), clear(b1)].\n[on(b1 floor)].\n",
     "syntax.pl:2: syntax error"),
    ("relation.pl", "[on(b1, floor), clear(b1)].\n\n[on(b1, floor), fly(b1)].\n",
     "relation.pl:3: fly(b1) is not a fact of the world's relations"),
    ("unbound.pl", "[on(b1, X), clear(b1)].\n", "unbound.pl:1: on(b1,_) is not a ground fact"),
    ("directive.pl", ":- initialization(halt).\n", "directive.pl:1: "),
    ("empty.pl", "% nothing\n", "empty.pl:1: no state in the file"),
    ("syntax.json", '[["on(b1, floor)", "clear(b1"]]', "syntax.json: state 1, fact 2: "),
    ("relation.json", '[["on(b1, floor)"], ["fly(b1)"]]',
     "relation.json: state 2: fly(b1) is not a fact of the world's relations"),
    ("notjson.json", '[["on(b1, floor)"],\n oops]', "notjson.json:2: not JSON"),
    ("task.json", '[{"state": ["on(b1, floor)"], "task": "unstack"}]',
     "task.json: state 1: task 'unstack' is not an instance of the evaluated task stack"),
])
def test_evaluate_bad_states_one_line_exit_2(policies, tmp_path: Path, capsys, name: str,
                                             text: str, message: str) -> None:
    states = tmp_path / name
    states.write_text(text)
    out = tmp_path / "out"
    assert _evaluate(policies["stack"], "stack", "--states", str(states),
                     "--out", str(out)) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()                 # refused before the folder is made


@pytest.mark.parametrize("flags, message", [
    (["--task", "fly", "--sizes", "3"], "--task 'fly': no such task"),
    (["--task", "stack", "--sizes", "3", "--episodes", "0"], "--episodes must be at least 1"),
    (["--task", "stack", "--sizes", "3,x"], "--sizes must be comma-separated"),
    (["--task", "stack", "--states", "nope.pl"], "--states nope.pl: no such file"),
    (["--task", "stack", "--sizes", "3", "--states", "x.pl"], "--states or --sizes"),
])
def test_evaluate_bad_flags_exit_2(policies, tmp_path: Path, capsys, flags: list[str],
                                   message: str) -> None:
    assert main(["evaluate", str(policies["stack"]), "--world", str(BLOCKS), *flags,
                 "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1, err


def test_evaluate_never_runs_a_states_file(policies, tmp_path: Path) -> None:
    """A directive in a states file is a term read as data, refused, never run."""
    marker = tmp_path / "ran"
    states = tmp_path / "states.pl"
    states.write_text(f":- open('{marker}', write, S), close(S).\n")
    assert _evaluate(policies["stack"], "stack", "--states", str(states),
                     "--out", str(tmp_path / "out")) == 2
    assert not marker.exists()


def test_evaluate_refuses_a_state_reached_below_its_optimum(policies, tmp_path: Path,
                                                            capsys) -> None:
    """A given state that breaks the world's invariants (b1 on both b2 and b3) made the
    world's optimal_steps/3 overestimate, and the evaluation reported 1.5 of optimal."""
    states = tmp_path / "two.pl"
    states.write_text("[on(b1, b2), on(b1, b3), on(b2, floor), on(b3, floor), clear(b1)].\n")
    out = tmp_path / "out"
    code = _evaluate(policies["on"], "on", "--states", str(states), "--out", str(out))
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1
    assert f"{display_path(str(states))}:1: the goal" in err and "fewer than the optimum" in err
    assert not (out / "results.json").exists()


@pytest.mark.parametrize("task", ["on(b1, b1)", "on(b1, b99)"])
def test_evaluate_refuses_a_task_instance_that_cannot_be_reached(policies, tmp_path: Path,
                                                                 capsys, task: str) -> None:
    """A task instance whose goal no state of the evaluated sizes holds is one line, exit 2,
    and nothing written (as relrl learn refuses it)."""
    out = tmp_path / "bad"
    assert _evaluate(policies["on"], task, "--sizes", "4", "--episodes", "2",
                     "--out", str(out)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot be reached" in err[0], err
    assert not (out / "results.json").exists()


def test_evaluate_refuses_an_object_the_world_lacks_at_its_default_sizes(policies,
                                                                        tmp_path: Path,
                                                                        capsys) -> None:
    """At 10, 20 and 50 blocks (too many states to search) b99 is still no block of the
    world: one line, exit 2 (it evaluated, with an 'optimum' from the world's formula)."""
    out = tmp_path / "bad"
    assert _evaluate(policies["on"], "on(b1, b99)", "--episodes", "2",
                     "--out", str(out)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "names b99" in err[0] and "10 objects" in err[0], err
    assert not (out / "results.json").exists()
