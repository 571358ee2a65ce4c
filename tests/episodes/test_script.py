"""Episode scripts: parsing, checking, and errors that name file:line."""

from __future__ import annotations

from pathlib import Path

import pytest

from relrl.cli import main
from relrl.episodes import EpisodeError, load_episode, parse_episode

ROOT = Path(__file__).resolve().parents[2]
FRUITS = ROOT / "examples" / "domains" / "fruits.pl"

GOOD = f"""\
[episode]
domain = "{FRUITS}"
seed = 3

[world]
perception = "symbolic"

[[phase]]
name = "a"
steps = 5
objects = false

[[phase]]
steps = 4
caregiver = "script"

[[event]]
t = 7
show = {{ left = "apple" }}
look = "left"
say = "apple"
"""


def test_examples_load() -> None:
    for name in ("experiment2.toml", "hello.toml"):
        ep = load_episode(ROOT / "examples" / "episodes" / name)
        assert ep.domain == FRUITS
        assert ep.steps > 0


def test_experiment2_has_the_papers_settings() -> None:
    ep = load_episode(ROOT / "examples" / "episodes" / "experiment2.toml")
    assert ep.learner == "etg"
    assert ep.learner_params == {"alpha": 0.2, "gamma": 0.9, "epsilon": 0.05}
    assert [p.steps for p in ep.phases] == [30, 70]
    assert ep.phases[0].objects is False
    assert ep.time_unit == "interaction" and ep.variation == "camera"
    assert ep.evaluation == {"every": 25, "runs": 5, "steps": 100, "policy": "behaviour"}
    assert ep.naming["executions"] == 5 and ep.naming["presentations"] == 150


def test_parse_good_script() -> None:
    ep = parse_episode(GOOD, "x.toml")
    assert ep.seed == 3 and ep.steps == 9
    assert ep.phase_at(5).name == "a" and ep.phase_at(6).name == "phase 2"
    (ev,) = ep.events
    assert (ev.t, ev.look, ev.show, ev.say, ev.line) == (7, "left", {"left": "apple"},
                                                        ["apple"], 17)


@pytest.mark.parametrize("old, new, line, words", [
    ("seed = 3", "seed = 3\nsed = 4", 4, "unknown key 'sed'"),
    ("steps = 4", "steps = -4", 14, "steps must be at least 1"),
    ('look = "left"', 'look = "lfet"', 20, "did you mean 'left'"),
    ('perception = "symbolic"', 'perception = "camera"', 6, "perception mode"),
    ("t = 7", "t = 70", 18, "after the last time unit"),
    ("seed = 3", "seed = 3\n[learner]\nalpha = 7", 5, "alpha must be in [0, 1]"),
    ("seed = 3", 'seed = "x"', 3, "seed must be a int"),
    ('show = { left = "apple" }', 'show = { centre = "apple" }', 19, "object place"),
    ("[world]", "[wrold]", 5, "did you mean [world]"),
    ("steps = 4", "steps = 4 4", 14, ""),              # a TOML syntax error
])
def test_errors_name_the_line(old: str, new: str, line: int, words: str) -> None:
    text = GOOD.replace(old, new, 1)
    with pytest.raises(EpisodeError) as err:
        parse_episode(text, "bad.toml")
    msg = str(err.value)
    assert msg.startswith(f"bad.toml:{line}: "), msg
    assert words in msg
    assert "\n" not in msg


def test_missing_domain_and_file(tmp_path: Path) -> None:
    with pytest.raises(EpisodeError, match="domain file 'nope.pl' not found"):
        parse_episode('[episode]\ndomain = "nope.pl"\n[[phase]]\nsteps=1\n',
                      tmp_path / "e.toml")
    with pytest.raises(EpisodeError, match="no such episode script"):
        load_episode(tmp_path / "missing.toml")


def test_cli_reports_bad_script_in_one_line(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(GOOD.replace("steps = 4", "steps = 0"))
    assert main(["run", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and f"{bad}:14:" in err


def test_cli_check(tmp_path: Path, capsys) -> None:
    good = tmp_path / "good.toml"
    good.write_text(GOOD)
    assert main(["run", str(good), "--check"]) == 0
    assert "9 time units" in capsys.readouterr().out


def test_every_problem_is_reported_with_its_line() -> None:
    text = (GOOD.replace("seed = 3", "seed = -1\nsed = 4")
            .replace('look = "left"', 'look = "lfet"')
            .replace("steps = 5", "steps = 0")
            + '\n[[event]]\nt = 2\nsay = "Hello there!"\nremove = "middle"\n')
    with pytest.raises(EpisodeError) as err:
        parse_episode(text, "bad.toml")
    lines = str(err.value).splitlines()
    assert lines[-1] == "7 problems in bad.toml", lines
    expected = [("bad.toml:3:", "seed must be an integer >= 0, not -1"),
                ("bad.toml:4:", "unknown key 'sed'"),
                ("bad.toml:11:", "steps must be at least 1, not 0"),
                ("bad.toml:21:", "did you mean 'left'"),
                ("bad.toml:26:", "say: 'Hello' is not a lower-case word"),
                ("bad.toml:26:", "say: 'there!' is not a lower-case word"),
                ("bad.toml:27:", "unknown place 'middle'")]
    for line, (where, words) in zip(lines, expected, strict=False):
        assert line.startswith(where) and words in line, (line, where, words)
    assert len(err.value.problems) == 7


def test_a_bad_phase_length_does_not_flag_every_event() -> None:
    with pytest.raises(EpisodeError) as err:
        parse_episode(GOOD.replace("steps = 4", "steps = -4"), "bad.toml")
    assert err.value.problems == ["bad.toml:14: steps must be at least 1, not -4"]


def test_many_problems_are_listed_up_to_a_limit() -> None:
    from relrl.episodes.script import MAX_LISTED

    events = "".join(f'[[event]]\nt = {t}\nlook = "nowhere"\n' for t in range(1, 31))
    with pytest.raises(EpisodeError) as err:
        parse_episode(GOOD.replace("steps = 4", "steps = 40") + events, "bad.toml")
    lines = str(err.value).splitlines()
    assert len(err.value.problems) == 30
    assert len(lines) == MAX_LISTED + 2 and lines[-2] == f"... and {30 - MAX_LISTED} more"


@pytest.mark.parametrize("value, words", [
    ('"../../x.pl"', "without '..'"), ('"/tmp/x.pl"', "without '..'"),
    ('"policies/"', "without '..'"), ('"summary.json"', "file of the run itself"),
    ('"trace.jsonl"', "file of the run itself")])
def test_policy_save_stays_inside_the_output_folder(value: str, words: str) -> None:
    with pytest.raises(EpisodeError, match=words) as err:
        parse_episode(GOOD.replace("seed = 3", f"seed = 3\npolicy_save = {value}"), "e.toml")
    assert str(err.value).startswith("e.toml:4: policy_save")


def test_policy_save_may_name_a_subfolder() -> None:
    ep = parse_episode(GOOD.replace("seed = 3", 'seed = 3\npolicy_save = "p/q/policy.pl"'))
    assert ep.policy_save == "p/q/policy.pl"


@pytest.mark.parametrize("old, new, words", [
    ("seed = 3", "seed = 3\n[learner]\nalpha = nan", "must be a finite number, not nan"),
    ("seed = 3", "seed = 3\n[learner]\nq_init = inf", "must be a finite number, not inf"),
    ('perception = "symbolic"', 'perception = "symbolic"\nlighting = nan', "lighting"),
])
def test_numbers_must_be_finite(old: str, new: str, words: str) -> None:
    with pytest.raises(EpisodeError, match=words):
        parse_episode(GOOD.replace(old, new), "e.toml")


def test_a_script_that_is_not_utf8_names_its_line(tmp_path: Path) -> None:
    path = tmp_path / "latin1.toml"
    path.write_bytes('[episode]\n\nname = "caf\xe9"\n'.encode("latin-1"))
    with pytest.raises(EpisodeError, match=r"latin1.toml:3: not UTF-8 text \(byte 0xe9\)"):
        load_episode(path)


def test_checking_is_linear_in_the_events() -> None:
    """The key lines are found through an index: examined lines grow with the script, not
    with its square (the old search scanned from the top for every event)."""
    from relrl.episodes import script

    seen = []
    real = script._Lines.__init__

    def spy(self, text):
        real(self, text)
        seen.append(self)

    body = GOOD.replace("steps = 4", "steps = 5000")
    events = "".join(f'[[event]]\nt = {t}\nlook = "left"\nsay = "apple"\n'
                     for t in range(1, 5001))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(script._Lines, "__init__", spy)
        ep = parse_episode(body + events, "many.toml")
    assert len(ep.events) == 5001 and ep.events[-1].line == 1 + body.count("\n") + 4 * 4999
    assert seen[0].scanned <= 2 * len(seen[0].lines)


@pytest.mark.parametrize("table", ["episode", "world", "event"])
def test_checking_many_unknown_keys_is_linear(table: str) -> None:
    """Each unknown key is located through an index of its section, made once: examined
    lines grow with the script, not with its square (2,500 / 5,000 / 10,000 unknown keys in
    one table took 2.3 / 7.1 / 25 s; now 0.15 / 0.30 / 0.57 s)."""
    from relrl.episodes import script

    seen = []
    real = script._Lines.__init__

    def spy(self, text):
        real(self, text)
        seen.append(self)

    keys = "".join(f"unknown_{i} = {i}\n" for i in range(2000))
    if table == "event":
        text = GOOD + "[[event]]\nt = 1\n" + keys
    else:
        text = GOOD.replace(f"[{table}]\n", f"[{table}]\n" + keys)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(script._Lines, "__init__", spy)
        with pytest.raises(EpisodeError) as info:
            parse_episode(text, "keys.toml")
    problems = info.value.problems
    assert len(problems) >= 2000
    last = text.splitlines().index("unknown_1999 = 1999") + 1
    assert problems[-1].startswith(f"keys.toml:{last}: unknown key 'unknown_1999'")
    assert seen[0].scanned <= 2 * len(seen[0].lines)


def test_evaluation_runs_are_bounded() -> None:
    with pytest.raises(EpisodeError, match="runs must be from 1 to 10000, not 1000000000"):
        parse_episode(GOOD + "[evaluation]\nruns = 1000000000\n", "e.toml")


@pytest.mark.parametrize("nest", ["[" * 3000 + "]" * 3000, "{ a = " * 3000 + "1" + " }" * 3000])
def test_a_script_nested_3000_deep_names_its_line(nest: str) -> None:
    """It used to end in a RecursionError inside tomllib."""
    text = GOOD + f"[learner]\nx = {nest}\n"
    with pytest.raises(EpisodeError, match=rf"deep.toml:{text.count(chr(10))}: arrays or "
                                           r"inline tables nested more than 32 deep"):
        parse_episode(text, "deep.toml")


def test_a_script_that_is_a_device_or_a_pipe_is_not_read(tmp_path: Path) -> None:
    import os

    (tmp_path / "zero.toml").symlink_to("/dev/zero")
    os.mkfifo(tmp_path / "pipe.toml")
    for name in ("zero.toml", "pipe.toml"):
        with pytest.raises(EpisodeError, match=rf"{name}: cannot read the episode script "
                                               r"\(not a regular file"):
            load_episode(tmp_path / name)
    (tmp_path / "big.toml").write_text(GOOD + "# " + "x" * (16 * 1024 * 1024) + "\n")
    with pytest.raises(EpisodeError, match=r"big.toml: cannot read the episode script "
                                           r"\(larger than 16 MB\)"):
        load_episode(tmp_path / "big.toml")
