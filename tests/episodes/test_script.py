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
