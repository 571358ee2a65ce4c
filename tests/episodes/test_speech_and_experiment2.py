"""Speech (espeak-ng -> pocketsphinx round trip) and Experiment 2 on rendered frames."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from relrl.episodes import RunOptions, parse_episode, run_episode
from relrl.experiments.exp2.measures import OUTCOMES, PAPER, rates
from relrl.speech import Recognizer, Speaker, SpeechError, sentence_for, synthesise

ROOT = Path(__file__).resolve().parents[2]


def test_recognise_synthesised_names(tmp_path: Path) -> None:
    words = ["apple", "lemon", "orange"]
    with Recognizer(words + ["attention"]) as rec:
        for word in words:
            assert rec.recognise_file(synthesise(word, tmp_path / f"{word}.wav")) == word


def test_unknown_word_is_a_user_error() -> None:
    with pytest.raises(SpeechError, match="not in the pocketsphinx dictionary"):
        Recognizer(["apple", "qzxv"])


def test_speaker_prints_without_espeak(capsys) -> None:
    import sys

    s = Speaker(aloud=False, stream=sys.stdout)
    s.say(sentence_for("apple", True))
    s.say(sentence_for("lemon", False))
    s.say(sentence_for(None, False))
    assert s.said == ["this is an apple", "is this a lemon?", "what is this?"]
    assert 'robot says: "this is an apple"' in capsys.readouterr().out


@pytest.mark.slow
def test_experiment2_small_on_rendered_frames(tmp_path: Path) -> None:
    text = (ROOT / "examples" / "episodes" / "experiment2.toml").read_text()
    text = text.replace('"../domains/fruits.pl"', f'"{ROOT / "examples/domains/fruits.pl"}"')
    for old, new in [("steps = 30", "steps = 3"), ("steps = 70", "steps = 7"),
                     ("every = 25", "every = 5"), ("runs = 5", "runs = 1"),
                     ("steps = 100", "steps = 4"), ("executions = 5", "executions = 2"),
                     ("presentations = 150", "presentations = 4"),
                     ("max_steps = 3000", "max_steps = 60")]:
        assert old in text
        text = text.replace(old, new, 1)
    ep = parse_episode(text, tmp_path / "exp2.toml")
    s = run_episode(ep, RunOptions(out=tmp_path / "out"))
    assert s["time_unit"] == "interaction" and s["units"] == 10 and s["steps"] > 10
    assert [p["units"] for p in s["evaluation"]] == [0, 5, 10]
    # regression: an evaluation must not send the learning world back to its first phase
    rows = [json.loads(x) for x in (tmp_path / "out" / "trace.jsonl").read_text().splitlines()]
    assert any(r["caregiver"]["objects"] for r in rows if r["phase"] == "fruits")
    assert all(0.0 <= p["cgi_mean"] <= 1.0 for p in s["evaluation"])
    t1 = s["table1"]
    assert len(t1["executions"]) == 2 and t1["paper"] == PAPER["table1"]
    for e in t1["executions"]:
        assert sum(e["counts"].values()) == e["presentations"]
        assert sum(sum(r.values()) for r in e["confusion"].values()) == e["presentations"]
        if e["presentations"]:
            assert e["counts"]["unknown"] >= 1   # the first presentation is always new
    assert t1["rates"] is None or set(t1["rates"]) == set(OUTCOMES)
    for f in ("trace.jsonl", "summary.json", "policy.pl", "cgi.png", "table1.png"):
        assert (tmp_path / "out" / f).exists(), f


def test_rates_are_mean_and_sd_of_percentages() -> None:
    ex = [{"presentations": 10, "counts": {"unknown": 1, "correct_guess": 2,
                                           "incorrect_guess": 0, "error": 0, "success": 7}},
          {"presentations": 20, "counts": {"unknown": 4, "correct_guess": 2,
                                           "incorrect_guess": 0, "error": 2, "success": 12}}]
    r = rates(ex)
    assert r["unknown"] == [15.0, 5.0] and r["success"] == [65.0, 5.0]
    assert r["error"] == [5.0, 5.0]
