"""bench/stepbench.py: the Prolog side of a control step recorded from a seeded run and replayed
in plain swipl, every decision checked (issue 13, item 4)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from bench.stepbench import record, replay
from relrl.cli import main
from relrl.errors import RelrlError


@pytest.fixture(scope="module")
def etg_recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return record(tmp_path_factory.mktemp("stepbench") / "etg.pl", "etg", steps=300, warmup=100)


@pytest.mark.slow
def test_recording_replays_with_the_same_decisions(etg_recording: Path) -> None:
    lines = etg_recording.read_text().splitlines()
    assert lines[0].startswith("stepbench(") and ",etg," in lines[0]
    assert sum(line.startswith("s(") for line in lines) == 400
    figures = replay(etg_recording, passes=1)
    assert figures["steps"] == 300 and figures["warmup"] == 100
    for how in ("direct", "gateway"):
        assert figures[how]["cpu_us_per_step"] > 0
        assert figures[how]["inferences_per_step"] > 100
    # the gateway's guarded call runs the same step and more
    assert figures["gateway"]["inferences_per_step"] > figures["direct"]["inferences_per_step"]


def test_a_different_decision_is_an_error_naming_the_step(etg_recording: Path,
                                                           tmp_path: Path) -> None:
    lines = etg_recording.read_text().splitlines()
    n = next(i for i, line in enumerate(lines) if i > 250 and line.startswith("s("))
    head, action = re.match(r"(.*,)(-?\d+)\)\)\.$", lines[n]).groups()
    lines[n] = f"{head}{(int(action) + 1) % 6})).".replace("\n", "")
    bad = tmp_path / "bad.pl"
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(RelrlError, match=rf"step {n} of the recording: the engine returned"):
        replay(bad, passes=1)


@pytest.mark.slow
def test_a_recording_is_data(tmp_path: Path, etg_recording: Path) -> None:
    first = etg_recording.read_text().splitlines()[0]
    bad = tmp_path / "bad.pl"
    bad.write_text(first + "\n:- halt.\n")
    with pytest.raises(RelrlError, match="stepbench_term"):
        replay(bad, passes=1)


@pytest.mark.slow
def test_external_learner_replays(tmp_path: Path) -> None:
    path = record(tmp_path / "q.pl", "qlearning", steps=100, warmup=20)
    assert ",external," in path.read_text().splitlines()[0]
    assert replay(path, passes=1)["learner"] == "external"


@pytest.mark.slow
def test_cli_prolog_step_with_profile(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bench", "--prolog-step", "--steps", "1000", "--profile", "--top", "5"]) == 0
    out = capsys.readouterr().out
    assert "inferences_per_step" in out
    rows = out.split("cumulative %, self %, calls per step\n")[1].splitlines()
    assert len(rows) == 5 and "relrl_" in out


@pytest.mark.parametrize("argv, message", [
    (["--profile"], "--profile and --learner go with --prolog-step"),
    (["--prolog-step", "--learner", "nope"], "unknown learner 'nope'"),
    (["--prolog-step", "--top", "0"], "--top must be at least 1"),
])
def test_cli_bad_flags(argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
                       ) -> None:
    assert main(["bench", *argv]) == 2
    assert message in capsys.readouterr().err


def test_the_harness_is_not_installed_with_the_package(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch,
                                                       capsys: pytest.CaptureFixture[str]
                                                       ) -> None:
    """bench/ is outside every package (pyproject's packages: relrl, perception, head; the
    package data: relrl/prolog/*.pl); without it, --prolog-step says where it lives."""
    import relrl.bench

    root = Path(relrl.bench.__file__).resolve().parents[1]
    assert not list((root / "prolog").glob("stepbench*")) and not (root / "relrl" /
                                                                   "stepbench.py").exists()
    monkeypatch.setattr(relrl.bench, "STEPBENCH", tmp_path / "stepbench.py")
    assert main(["bench", "--prolog-step"]) == 2
    assert "source tree" in capsys.readouterr().err
