"""Speech in and out for episodes: the caregiver's words as ``hear(Word)``, the robot's naming.

* **Out** -- :class:`Speaker` says a sentence with ``espeak-ng`` (Debian package
  ``espeak-ng``) when it is installed, and otherwise prints it; either way the sentence is
  kept in :attr:`Speaker.said`.
* **In** -- :class:`Recognizer` recognises one word of a small vocabulary (the fruit names)
  offline with pocketsphinx (the optional ``speech`` extra: ``pip install relrl[speech]``),
  using the English acoustic model shipped in the pocketsphinx wheel and a JSGF grammar of the
  names instead of the general language model. :func:`synthesise` writes a word spoken by
  espeak-ng to a WAV file, which is how the tests make a caregiver's voice.

Words typed in a live session or written in the script need none of this.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
import wave
from collections.abc import Iterable
from pathlib import Path
from typing import Self

import numpy as np

from relrl.errors import UserError

__all__ = [
    "Recognizer",
    "Speaker",
    "SpeechError",
    "espeak_available",
    "sentence_for",
    "synthesise",
]


class SpeechError(UserError):
    """Speech recognition or synthesis is unavailable or failed."""


def espeak_available() -> bool:
    """True when the ``espeak-ng`` program is on the PATH."""
    return shutil.which("espeak-ng") is not None


def sentence_for(name: str | None, confident: bool) -> str:
    """What the robot says when it points at a fruit (declarative pointing)."""
    if name is None:
        return "what is this?"
    article = "an" if name[:1] in "aeiou" else "a"
    return f"this is {article} {name}" if confident else f"is this {article} {name}?"


class Speaker:
    """Says sentences aloud with espeak-ng, or prints them.

    Args:
        voice: espeak-ng voice (``en``, ``pt``, ...).
        aloud: use espeak-ng when available (``False``: only print).
        stream: where printed sentences go (``None``: keep them silent, only in :attr:`said`).
    """

    def __init__(self, voice: str = "en", *, aloud: bool = True, stream=None) -> None:
        self.voice = voice
        self.aloud = aloud and espeak_available()
        self.stream = stream
        self.said: list[str] = []

    def say(self, text: str) -> None:
        """Say ``text`` (non-blocking with espeak-ng; printed otherwise)."""
        self.said.append(text)
        if self.aloud:
            subprocess.Popen(["espeak-ng", "-v", self.voice, text],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        elif self.stream is not None:
            print(f'robot says: "{text}"', file=self.stream, flush=True)

    def close(self) -> None:
        """Nothing to release (safe twice)."""


def synthesise(text: str, path: str | Path, voice: str = "en") -> Path:
    """Write ``text`` spoken by espeak-ng to the WAV file ``path``.

    Raises:
        SpeechError: espeak-ng is not installed (Debian package ``espeak-ng``).
    """
    if not espeak_available():
        raise SpeechError("espeak-ng is not installed; install the Debian package espeak-ng")
    path = Path(path)
    subprocess.run(["espeak-ng", "-v", voice, "-w", str(path), text], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return path


def _read_wav(path: str | Path, rate: int = 16000) -> np.ndarray:
    """Mono 16-bit samples of a WAV file, resampled (linearly) to ``rate``."""
    with wave.open(str(path)) as f:
        if f.getsampwidth() != 2:
            raise SpeechError(f"{path}: only 16-bit WAV files are supported")
        data = np.frombuffer(f.readframes(f.getnframes()), np.int16)
        channels, src = f.getnchannels(), f.getframerate()
    if channels > 1:
        data = data.reshape(-1, channels).mean(axis=1).astype(np.int16)
    if src != rate:
        x = np.arange(0, len(data), src / rate)
        data = np.interp(x, np.arange(len(data)), data).astype(np.int16)
    return data


class Recognizer:
    """Offline recognition of one word among ``words`` (pocketsphinx + a JSGF grammar).

    Args:
        words: the vocabulary (lower-case words in pocketsphinx's English dictionary).

    Raises:
        SpeechError: pocketsphinx is not installed, or a word is not in its dictionary.
    """

    def __init__(self, words: Iterable[str]) -> None:
        try:
            from pocketsphinx import Decoder, get_model_path
        except ImportError:
            raise SpeechError("speech recognition needs the optional extra: "
                              "pip install 'relrl[speech]' (pocketsphinx)") from None
        self.words = sorted({w.lower() for w in words})
        if not self.words:
            raise SpeechError("the recogniser needs at least one word")
        model = Path(get_model_path()) / "en-us"
        dictionary = model / "cmudict-en-us.dict"
        known = set()
        with open(dictionary, encoding="utf-8") as fh:
            for line in fh:
                known.add(line.split(" ", 1)[0])
        missing = [w for w in self.words if w not in known]
        if missing:
            raise SpeechError(f"not in the pocketsphinx dictionary: {', '.join(missing)}")
        self._dir = tempfile.TemporaryDirectory(prefix="relrl-speech-")
        grammar = Path(self._dir.name) / "names.gram"
        grammar.write_text("#JSGF V1.0;\ngrammar names;\npublic <name> = "
                           + " | ".join(self.words) + ";\n", encoding="utf-8")
        self.decoder = Decoder(hmm=str(model / "en-us"), dict=str(dictionary),
                               jsgf=str(grammar), samprate=16000, loglevel="FATAL")

    def recognise(self, samples: np.ndarray) -> str | None:
        """The word in 16 kHz mono int16 ``samples``, or ``None`` if nothing was recognised."""
        d = self.decoder
        d.start_utt()
        d.process_raw(np.asarray(samples, np.int16).tobytes(), full_utt=True)
        d.end_utt()
        hyp = d.hyp()
        text = hyp.hypstr.strip() if hyp is not None else ""
        return text.split()[0] if text else None

    def recognise_file(self, path: str | Path) -> str | None:
        """The word spoken in a WAV file."""
        return self.recognise(_read_wav(path))

    def close(self) -> None:
        """Remove the grammar file (safe twice)."""
        self._dir.cleanup()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
