"""Hearing words: the segmenter, ``--audio FILE.wav`` through the recogniser into
``hear(Word)``, and a missing microphone as one line."""

from __future__ import annotations

import json
import wave
from pathlib import Path

import numpy as np
import pytest

from relrl.cli import main
from relrl.listen import RATE, AudioFileWords, Segmenter
from relrl.speech import SpeechError, _read_wav, synthesise
from tests.monitor.conftest import episode


def _wav(path: Path, samples: np.ndarray, rate: int = RATE) -> Path:
    with wave.open(str(path), "wb") as f:
        f.setnchannels(1)
        f.setsampwidth(2)
        f.setframerate(rate)
        f.writeframes(np.asarray(samples, np.int16).tobytes())
    return path


def _silence(seconds: float) -> np.ndarray:
    rng = np.random.default_rng(0)
    return rng.normal(0, 30, int(seconds * RATE)).astype(np.int16)  # a quiet room


def test_segmenter_finds_each_utterance() -> None:
    t = np.arange(int(0.4 * RATE)) / RATE
    tone = (4000 * np.sin(2 * np.pi * 220 * t)).astype(np.int16)
    audio = np.concatenate([_silence(0.5), tone, _silence(0.6), tone, _silence(0.6),
                            tone[:400], _silence(0.6)])  # the last is too short: a click
    seg = Segmenter()
    found = []
    for i in range(0, len(audio), 1000):   # blocks as a microphone delivers them
        found += seg.feed(audio[i:i + 1000])
    found += seg.flush()
    assert len(found) == 2
    for utterance in found:
        assert 0.4 * RATE <= len(utterance) <= 1.2 * RATE


def _spoken(tmp_path: Path, words: list[str], gap: float = 1.0) -> Path:
    parts = [_silence(0.8)]
    for word in words:
        parts += [_read_wav(synthesise(word, tmp_path / f"{word}.wav")), _silence(gap)]
    return _wav(tmp_path / "caregiver.wav", np.concatenate(parts))


@pytest.mark.slow
def test_audio_file_is_heard_at_its_time_units(tmp_path: Path) -> None:
    wav = _spoken(tmp_path, ["apple", "lemon"])
    source = AudioFileWords(wav, ["apple", "lemon", "orange", "attention"], 0.5)
    heard = {}
    for unit in range(1, 20):
        for word in source.poll():
            heard[word] = unit
    source.close()
    assert sorted(heard) == ["apple", "lemon"]
    assert heard["apple"] < heard["lemon"]


@pytest.mark.slow
def test_run_with_audio_reaches_hear_word(tmp_path: Path) -> None:
    wav = _spoken(tmp_path, ["orange", "apple"])
    script = episode(tmp_path, steps=20, perception="symbolic")
    out = tmp_path / "out"
    assert main(["run", str(script), "--audio", str(wav), "--out", str(out),
                 "--no-plots"]) == 0
    rows = [json.loads(x) for x in (out / "trace.jsonl").read_text().splitlines()]
    # words from the file (the protocol caregiver also names a fruit she shares with the
    # robot, in mode "joint"; the robot perceives hers in the next time unit)
    joint = {r["t"] + 1 for r in rows if r["caregiver"]["mode"] == "joint"}
    heard = [(r["t"], p) for r in rows for p in r["percepts"]
             if p in ("hear(orange)", "hear(apple)") and r["t"] not in joint]
    assert [p for _, p in heard] == ["hear(orange)", "hear(apple)"], heard
    # the same file is heard at the same time units every time
    again = tmp_path / "again"
    assert main(["run", str(script), "--audio", str(wav), "--out", str(again),
                 "--no-plots"]) == 0
    assert (out / "trace.jsonl").read_text() == (again / "trace.jsonl").read_text()


@pytest.mark.parametrize("args", [["--mic", "no-such-microphone-xyz"],
                                  ["--audio", "missing.wav"],
                                  ["--audio", "{bad}"]])
def test_missing_audio_is_one_line(tmp_path: Path, capsys, args: list[str]) -> None:
    (tmp_path / "bad.wav").write_bytes(b"RIFF....not a wave")
    args = [a.replace("{bad}", str(tmp_path / "bad.wav")) for a in args]
    script = episode(tmp_path, steps=5, perception="symbolic")
    assert main(["run", str(script), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("relrl run: "), err


def test_the_default_microphone_opens_or_is_missing_in_one_line() -> None:
    import sounddevice as sd

    from relrl.listen import MicWords

    try:
        sd.query_devices(kind="input")
    except (ValueError, sd.PortAudioError):  # no microphone here (CI): one clear error
        with pytest.raises(SpeechError, match="no audio input device"):
            MicWords(["apple"])
        return
    mic = MicWords(["apple"])  # a machine with a microphone: it opens and closes
    assert mic.poll() == [] or isinstance(mic.poll(), list)
    mic.close()
    mic.close()
