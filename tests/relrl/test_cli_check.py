"""``relrl check``: valid domains list their codes; every bad input is one line, exit 2."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from relrl.cli import main
from tests.conftest import FRUITS, ROOT, SIS


def test_check_fruits_lists_codes(capsys) -> None:
    assert main(["check", str(FRUITS)]) == 0
    out = capsys.readouterr().out
    assert "    0            1  stimulus(face)" in out
    assert "   14        16384  fact(looking_fruit(object))" in out
    assert "socialize: bias=1.0, recurrent_weight=1.0, delta=0.2, threshold=0.5" in out
    assert "input hear(attention)  weight -1.5" in out
    assert "forbidden(name_object)" in out
    assert "is valid" in out


def test_check_sis_is_valid(capsys) -> None:
    assert main(["check", str(SIS)]) == 0
    assert "warning" not in capsys.readouterr().err     # its bias names no place


def test_a_bias_that_grows_with_the_world_warns(tmp_path, capsys) -> None:
    """A #place constant per place (as the SIS's bias once had) is valid but warned about,
    with file and line, also with -q."""
    text = SIS.read_text().replace("rmode(head_at(#(face_place))).",
                                   "rmode(head_at(#place)).")
    text += "".join(f"rconst(place, {p}).\n" for p in
                    ("centre", "left", "left_down", "down", "right_down", "right"))
    path = tmp_path / "old_bias.pl"
    path.write_text(text)
    line = text.splitlines().index("rmode(head_at(#place)).") + 1
    assert main(["check", "-q", str(path)]) == 0
    err = capsys.readouterr().err
    assert f"old_bias.pl:{line}: warning: rconst type place has a constant for each of 6 " \
        "responses' arguments" in err
    assert len(err.strip().splitlines()) == 1


BAD = {
    "syntax": ("stimulus(face).\nresponse(look(left).\n", ":2: error: Syntax error"),
    "undefined": ("stimulus(face).\nresponse(r).\nfact(f(face)).\nf(face) :- nothere(face).\n",
                  ":4: f/1 calls undefined predicate nothere/1"),
    "undeclared_response": ("stimulus(face).\nresponse(r).\nforbidden(jump) :- see(face).\n",
                            ":3: response jump is used but not declared"),
    "duplicate": ("stimulus(face).\nstimulus(face).\nresponse(r).\n",
                  ":2: stimulus face is declared twice"),
    "non_numeric": ("stimulus(face).\nresponse(r).\nnecessity(n).\nunit(n, bias, high).\n"
                    "unit(n, recurrent_weight, 1).\nunit(n, delta, 0).\nunit(n, threshold, 0.5).\n",
                    ":4: unit parameter bias of necessity n must be a number, not high"),
    "unknown_param": ("stimulus(face).\nresponse(r).\nnecessity(n).\nunit(n, bias, 1).\n"
                      "unit(n, recurrent_weight, 1).\nunit(n, delta, 0).\n"
                      "unit(n, threshold, 0.5).\n"
                      "unit(n, gain, 2).\n", ":8: unknown unit parameter gain of necessity n"),
    "missing_param": ("stimulus(face).\nresponse(r).\nnecessity(n).\nunit(n, bias, 1).\n",
                      ":3: necessity n has no recurrent_weight parameter"),
    "singleton": ("stimulus(face).\nresponse(r).\nfact(f(face)).\nf(X) :- see(face).\n",
                  ":4: warning: Singleton variables: [X]"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_domain_one_line_exit_2(case: str, write_domain, capsys) -> None:
    text, expected = BAD[case]
    path = write_domain(text)
    assert main(["check", "--quiet", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{path}{expected}" in err, err
    assert "Traceback" not in err


def test_library_predicates_count_as_defined_others_do_not(write_domain, capsys) -> None:
    """A rule may call an autoloadable library predicate (library(ugraphs), library(heaps),
    library(lists)); a predicate defined nowhere is reported."""
    path = write_domain("stimulus(face).\nresponse(r).\nfact(f(face)).\n"
                        "f(face) :- vertices_edges_to_ugraph([a], [], _), empty_heap(_), "
                        "last([1], _).\n"
                        "fact(g(face)).\ng(face) :- nothere(face).\n")
    assert main(["check", "--quiet", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"{path}:6: g/1 calls undefined predicate nothere/1", "1 problem"], err


def test_missing_file_exit_2(capsys) -> None:
    assert main(["check", "nowhere/none.pl"]) == 2
    assert "nowhere/none.pl: error: no such file" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_process_has_no_traceback(write_domain) -> None:
    path = write_domain("stimulus(face).\nresponse(look(left).\n")
    proc = subprocess.run([sys.executable, "-m", "relrl.cli", "check", str(path)],
                          capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert f"{path}:2:" in proc.stderr


def test_bad_flag_exit_2(capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["check", "--no-such-flag", str(FRUITS)])
    assert exc.value.code == 2


def _without_swipl(argv: list[str], tmp_path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items()
           if k not in ("LIBSWIPL_PATH", "SWI_HOME_DIR")}
    env["PATH"] = str(tmp_path)           # an empty folder: no swipl
    return subprocess.run([sys.executable, "-m", "relrl.cli", *argv], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_without_swi_prolog_a_command_that_needs_it_says_so(tmp_path) -> None:
    """No swipl on the PATH (and no LIBSWIPL_PATH): one line saying so, exit 2."""
    proc = _without_swipl(["check", "examples/domains/sis.pl"], tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        "relrl check: SWI-Prolog is not installed: swipl is not on the PATH (make setup "
        "installs it; or set LIBSWIPL_PATH and SWI_HOME_DIR)"]


@pytest.mark.parametrize("argv", [["--help"], ["--version"], ["experiment", "worlds", "--help"],
                                  ["head", "--help"], ["report", "--help"]])
@pytest.mark.slow
def test_without_swi_prolog_help_and_the_other_commands_work(argv: list[str],
                                                             tmp_path) -> None:
    """The options need no Prolog (the learner registry is asked when a command runs): help
    and the commands that do not use Prolog (head, perceive, report) run without it."""
    proc = _without_swipl(argv, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout and not proc.stderr
