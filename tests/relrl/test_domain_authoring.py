"""Domain authoring: declarations and definitions interleave and spread over files;
``relrl check --world`` warns about facts a world can never make hold; ``:add`` warns about a
percept the domain does not know."""

from __future__ import annotations

import io
import shutil
import subprocess

import pytest

from relrl.cli import main
from relrl.kb import KnowledgeBase
from relrl.shell import Shell
from relrl.terms import Var
from tests.conftest import FRUITS, ROOT, SIS

INTERLEAVED = """\
stimulus(face).
fact(frontal(face)).
frontal(face) :- percept(pose(face, frontal)).
stimulus(object).
fact(red(object)).
red(object) :- see(object), percept(colour(object, red)).
response(look(centre)).
necessity(socialize).
unit(socialize, bias, 1.0).
unit(socialize, recurrent_weight, 1.0).
unit(socialize, delta, 0.2).
unit(socialize, threshold, 0.5).
satisfier(socialize, see(frontal(face)), 0.95).
response(look(left)).
"""


def test_declarations_and_definitions_interleave(write_domain, capsys) -> None:
    path = write_domain(INTERLEAVED)
    assert main(["check", str(path)]) == 0, capsys.readouterr().err
    captured = capsys.readouterr()
    assert "not together" not in captured.err and "relrl_kb_" not in captured.err
    assert "    2            4  fact(frontal(face))" in captured.out
    assert "  look(left)" in captured.out


def test_a_domain_spreads_over_files(write_domain) -> None:
    first = write_domain(INTERLEAVED, "first.pl")
    more = write_domain("response(look(right)).\nstimulus(attention).\n", "more.pl")
    with KnowledgeBase(first, more) as kb:
        assert kb.declarations("response") == [("look", "centre"), ("look", "left"),
                                               ("look", "right")]
        assert kb.declarations("stimulus") == ["face", "object", "attention"]


SOCIALIZE = {("socialize", "bias"): 1.0, ("socialize", "recurrent_weight"): 1.0,
             ("socialize", "delta"): 0.2, ("socialize", "threshold"): 0.5}


@pytest.mark.parametrize("domain", [SIS, FRUITS], ids=["sis", "fruits"])
def test_a_copied_domain_still_includes_the_shared_socialize_unit(domain, tmp_path) -> None:
    """The shipped domains include the socialize unit through relrl_domains(socialize), not
    by a path beside them: a copy in a folder of its own loads, through relrl and in plain
    swipl, with the unit's parameters."""
    copy = tmp_path / domain.name
    shutil.copy(domain, copy)
    with KnowledgeBase(copy) as kb:
        assert kb.declarations("necessity") == ["socialize"]
        units = {(n, p): v for _, n, p, v in kb.find("unit", Var(), Var(), Var())}
    assert units == SOCIALIZE
    goal = ("forall(unit(N, P, V), format('~w ~w ~w~n', [N, P, V])), halt")
    proc = subprocess.run(["swipl", "-q", "-g", goal, "-t", "halt(1)",
                           str(ROOT / "prolog" / "relrl.pl"), str(copy)],
                          capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert {tuple(line.split()[:2]): float(line.split()[2])
            for line in proc.stdout.splitlines()} == SOCIALIZE


WRONG_WORLD = """\
stimulus(face).
stimulus(toy).
fact(points_left(face)).
points_left(face) :- percept(pose(face, left)).
fact(points_left_2(face)).
points_left_2(face) :- percept(pose(face, left_2)).
fact(either(face)).
either(face) :- ( percept(pose(face, left)) ; percept(pose(face, left_2)) ).
fact(via_helper(face)).
via_helper(face) :- helper(left).
helper(P) :- see(face), percept(pose(face, P)).
fact(not_left(face)).
not_left(face) :- \\+ percept(pose(face, left)).
fact(toy_left(toy)).
toy_left(toy) :- at(toy, left).
response(look(centre)).
"""


def _warnings(err: str) -> list[str]:
    return [line.split(": warning: ")[1] for line in err.splitlines() if ": warning: " in line]


def test_check_world_warns_about_facts_that_can_never_hold(write_domain, capsys) -> None:
    path = write_domain(WRONG_WORLD)
    assert main(["check", "-q", "--world", "sis", str(path)]) == 2
    err = capsys.readouterr().err
    assert _warnings(err) == [
        "fact points_left_2(face) can never hold in this world: it needs pose(face, left_2), "
        "which the world never perceives (world sis)"]
    assert err.splitlines()[0].startswith(f"{path.name}:5: warning: ") or \
        f"{path}:5: warning: " in err
    assert main(["check", "-q", "--world", "episodes", str(path)]) == 2
    warnings = _warnings(capsys.readouterr().err)
    assert [w.split(" can never")[0] for w in warnings] == [
        "fact points_left(face)", "fact via_helper(face)", "fact toy_left(toy)"]
    assert "it needs pose(face, left)," in warnings[0] and "(world episodes)" in warnings[0]


def test_each_example_fits_its_own_world_and_not_the_other(capsys) -> None:
    assert main(["check", "-q", "--world", "sis", str(SIS)]) == 0
    assert main(["check", "-q", "--world", "fruits", str(FRUITS)]) == 0
    assert main(["check", "-q", "--world", "episodes", str(FRUITS)]) == 0
    capsys.readouterr()
    assert main(["check", "-q", "--world", "episodes", str(SIS)]) == 2
    warnings = _warnings(capsys.readouterr().err)
    assert "fact gaze_left(face) can never hold in this world: it needs pose(face, left)," \
        in warnings[0]
    assert main(["check", "-q", "--world", "sis", str(FRUITS)]) == 2
    warnings = _warnings(capsys.readouterr().err)
    assert warnings[0] == "stimulus object is never perceived in this world (world sis)"


def test_unknown_world_is_one_line(capsys) -> None:
    with pytest.raises(SystemExit) as info:
        main(["check", "--world", "mars", str(SIS)])
    assert info.value.code == 2
    assert capsys.readouterr().err.count("\n") == 1


@pytest.fixture
def shell():
    kb = KnowledgeBase(FRUITS)
    out = io.StringIO()
    yield Shell(kb, out, timeout=2), out
    kb.close()


def test_add_warns_about_a_percept_the_domain_does_not_know(shell) -> None:
    sh, out = shell
    sh.run_lines([":add se(face), see(face), pose(face, left), pose(face, left_1), "
                  "colour(object, red), at(object, left), see(dog)\n", ":memory\n"])
    lines = out.getvalue().splitlines()
    assert lines[0] == "inserted 7 elements"
    # fruits.pl's relational view (for tg) reads every see(_) and pose(_, _) in working
    # memory (sees(Thing), gaze(Who, Place)), so only the typo is unread
    assert [line for line in lines if line.startswith("warning:")] == [lines[1]]
    assert lines[1].split(" is not")[0] == "warning: se(face)"
    assert "no stimulus, fact or rule perceives it" in lines[1]
    assert "age 0   se(face)" in out.getvalue()             # a warning, not a refusal
    assert sh.errors == 0
