"""Words the robot hears during a session: typed, from a microphone, or from a WAV file.

Every source gives the words heard since the last time unit (:meth:`WordSource.poll`, once
per time unit); the session makes each one a percept ``hear(Word)``.

* :class:`TypedWords` -- lines typed on standard input (``relrl run --live``).
* :class:`MicWords` -- live capture with sounddevice (PortAudio: the optional ``speech``
  extra and the Debian package ``libportaudio2``): blocks go to a thread that cuts them into
  utterances (:class:`Segmenter`) and recognises each with the JSGF-grammar
  :class:`~relrl.speech.Recognizer`.
* :class:`AudioFileWords` -- a recorded WAV file through the same segmenter and recogniser,
  ``seconds_per_unit`` of audio per time unit (the session's clock, not the wall clock, so a
  run with ``--audio`` hears the same words at the same time units every time).
"""

from __future__ import annotations

import abc
import logging
import queue
import re
import sys
import threading
import wave
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from relrl.speech import SpeechError

__all__ = ["AudioFileWords", "Listener", "MicWords", "Segmenter", "TypedWords",
           "WordSource", "open_microphone"]

log = logging.getLogger(__name__)

RATE = 16000
#: what a typed word may be.
_WORD = re.compile(r"[a-z][a-z0-9_]*")
#: samples per analysis frame (30 ms at 16 kHz).
FRAME = 480


class WordSource(abc.ABC):
    """Something that hears words; :meth:`poll` is called once per time unit."""

    @abc.abstractmethod
    def poll(self) -> list[str]:
        """The words heard since the last call."""

    def close(self) -> None:  # noqa: B027 - an optional hook
        """Release the source (safe twice)."""


class Segmenter:
    """Cuts 16 kHz int16 audio into utterances by short-time energy.

    A frame (30 ms) is voiced when its RMS is above ``max(min_rms, ratio x noise)``, the noise
    floor following the quietest frames. An utterance starts at the first voiced frame (with
    ``pre_ms`` of audio before it) and ends after ``silence_ms`` of unvoiced frames; with less
    than ``min_ms`` of voiced frames it is dropped (a click), longer than ``max_ms`` it is
    cut.
    """

    def __init__(self, *, min_rms: float = 300.0, ratio: float = 3.0, silence_ms: int = 300,
                 min_ms: int = 150, max_ms: int = 3000, pre_ms: int = 150) -> None:
        self.min_rms, self.ratio = min_rms, ratio
        self.silence = max(1, silence_ms * RATE // 1000 // FRAME)
        self.min_len = min_ms * RATE // 1000
        self.max_len = max_ms * RATE // 1000
        self.pre = max(1, pre_ms * RATE // 1000 // FRAME)
        self.noise = min_rms / ratio
        self._rest = np.zeros(0, np.int16)
        self._pre: list[np.ndarray] = []
        self._voice: list[np.ndarray] | None = None
        self._quiet = 0
        self._voiced = 0

    def feed(self, samples: np.ndarray) -> list[np.ndarray]:
        """Add samples; returns the utterances completed by them."""
        data = np.concatenate([self._rest, np.asarray(samples, np.int16).ravel()])
        n = len(data) // FRAME * FRAME
        self._rest = data[n:]
        done = []
        for i in range(0, n, FRAME):
            frame = data[i:i + FRAME]
            rms = float(np.sqrt(np.mean(frame.astype(np.float64) ** 2)))
            voiced = rms > max(self.min_rms, self.ratio * self.noise)
            if not voiced:
                self.noise = 0.95 * self.noise + 0.05 * rms
            if self._voice is None:
                if voiced:
                    self._voice, self._quiet, self._voiced = [*self._pre, frame], 0, 1
                    self._pre = []
                else:
                    self._pre = (self._pre + [frame])[-self.pre:]
                continue
            self._voice.append(frame)
            self._quiet = 0 if voiced else self._quiet + 1
            self._voiced += voiced
            if self._quiet >= self.silence or len(self._voice) * FRAME >= self.max_len:
                done += self._end()
        return done

    def _end(self) -> list[np.ndarray]:
        voice, self._voice = self._voice or [], None
        if self._voiced * FRAME < self.min_len:  # a click, not a word
            return []
        return [np.concatenate(voice)]

    def flush(self) -> list[np.ndarray]:
        """The utterance still open at the end of the audio, if any."""
        return self._end() if self._voice is not None else []


class Listener:
    """A segmenter and a recogniser: audio in, words out.

    Args:
        words: the vocabulary (see :class:`relrl.speech.Recognizer`).
        segmenter: how to cut utterances (default :class:`Segmenter`).
    """

    def __init__(self, words: Iterable[str], segmenter: Segmenter | None = None) -> None:
        from relrl.speech import Recognizer

        self.recognizer = Recognizer(words)
        self.segmenter = segmenter or Segmenter()

    def _words(self, utterances: list[np.ndarray]) -> list[str]:
        out = []
        for audio in utterances:
            word = self.recognizer.recognise(audio)
            log.debug("utterance of %.2f s recognised as %r", len(audio) / RATE, word)
            if word:
                out.append(word)
        return out

    def feed(self, samples: np.ndarray) -> list[str]:
        """Words completed by these samples."""
        return self._words(self.segmenter.feed(samples))

    def flush(self) -> list[str]:
        """The word of an utterance still open."""
        return self._words(self.segmenter.flush())

    def close(self) -> None:
        """Release the recogniser (safe twice)."""
        self.recognizer.close()


class TypedWords(WordSource):
    """Words typed on a stream (standard input), read by a daemon thread; bytes that are not
    UTF-8, and tokens that are not words (letters, digits, ``_``), are skipped with a line
    on standard error."""

    def __init__(self, stream: Any = None) -> None:
        self._queue: queue.Queue[str] = queue.Queue()
        stream = stream if stream is not None else getattr(sys.stdin, "buffer", sys.stdin)
        threading.Thread(target=self._read, args=(stream,), daemon=True,
                         name="relrl-typed").start()

    def _read(self, stream: Any) -> None:
        for raw in stream:
            line = raw.decode("utf-8", "replace") if isinstance(raw, bytes) else raw
            for word in line.strip().lower().split():
                if _WORD.fullmatch(word):
                    self._queue.put(word)
                else:
                    print(f"relrl run: ignored {word!r}: type words of letters, digits and _",
                          file=sys.stderr, flush=True)

    def poll(self) -> list[str]:
        return _drain(self._queue)


def _drain(q: queue.Queue[str]) -> list[str]:
    out = []
    while True:
        try:
            out.append(q.get_nowait())
        except queue.Empty:
            return out


class AudioFileWords(WordSource):
    """A WAV file heard ``seconds_per_unit`` seconds per time unit.

    Raises:
        SpeechError: the file is missing or not a 16-bit WAV; no recogniser.
    """

    def __init__(self, path: str | Path, words: Iterable[str],
                 seconds_per_unit: float = 0.5) -> None:
        from relrl.speech import _read_wav

        path = Path(path)
        if not path.is_file():
            raise SpeechError(f"--audio {path}: no such file")
        if not seconds_per_unit > 0:
            raise SpeechError(f"audio seconds per time unit must be positive, not "
                              f"{seconds_per_unit}")
        try:
            self.samples = _read_wav(path, RATE)
        except (wave.Error, EOFError, OSError) as exc:
            raise SpeechError(f"--audio {path}: not a readable WAV file ({exc})") from None
        self.listener = Listener(words)
        self.step = int(round(seconds_per_unit * RATE))
        self.pos = 0

    def poll(self) -> list[str]:
        if self.pos >= len(self.samples):
            return []
        chunk = self.samples[self.pos:self.pos + self.step]
        self.pos += self.step
        words = self.listener.feed(chunk)
        if self.pos >= len(self.samples):
            words += self.listener.flush()
        return words

    def close(self) -> None:
        self.listener.close()


def open_microphone(device: str | int | None) -> tuple[Any, int, float]:
    """The sounddevice module, the input device and its sample rate.

    Raises:
        SpeechError: sounddevice or PortAudio missing, or no such input device.
    """
    try:
        import sounddevice as sd
    except ImportError:
        raise SpeechError("the microphone needs the optional extra: pip install "
                          "'relrl[speech]' (sounddevice)") from None
    except OSError:
        raise SpeechError("the microphone needs PortAudio: install the Debian package "
                          "libportaudio2") from None
    dev: str | int | None = int(device) if isinstance(device, str) and device.isdigit() \
        else device
    try:
        info = sd.query_devices(dev, kind="input")
    except (ValueError, sd.PortAudioError) as exc:
        what = "no audio input device" if dev is None else f"no audio input device {device!r}"
        raise SpeechError(f"{what} ({str(exc).splitlines()[0]}); list the devices with "
                          "python -m sounddevice") from None
    return sd, info["index"], float(info["default_samplerate"])


class MicWords(WordSource):
    """Live microphone capture, recognised in a thread of its own.

    Args:
        words: the vocabulary.
        device: a sounddevice input device (index or name; ``None``: the default).

    Raises:
        SpeechError: no microphone, PortAudio or recogniser.
    """

    def __init__(self, words: Iterable[str], device: str | int | None = None) -> None:
        sd, index, rate = open_microphone(device)
        self.listener = Listener(words)
        self.rate = rate
        self._blocks: queue.Queue[np.ndarray | None] = queue.Queue(maxsize=200)
        self._words: queue.Queue[str] = queue.Queue()
        self._thread = threading.Thread(target=self._recognise, daemon=True,
                                        name="relrl-mic")
        self._thread.start()
        try:
            self.stream = sd.InputStream(device=index, channels=1, samplerate=rate,
                                         dtype="int16", callback=self._callback)
            self.stream.start()
        except sd.PortAudioError as exc:
            self._blocks.put(None)
            raise SpeechError(f"cannot open the microphone {device!r}: {exc}") from None
        log.info("listening on input device %s at %.0f Hz", index, rate)

    def _callback(self, data: np.ndarray, frames: int, when: Any, status: Any) -> None:
        try:
            self._blocks.put_nowait(data[:, 0].copy())
        except queue.Full:  # the recogniser is behind: drop audio, never block PortAudio
            pass

    def _recognise(self) -> None:
        while (block := self._blocks.get()) is not None:
            if self.rate != RATE:
                x = np.arange(0, len(block), self.rate / RATE)
                block = np.interp(x, np.arange(len(block)), block).astype(np.int16)
            for word in self.listener.feed(block):
                log.info("heard %r", word)
                self._words.put(word)

    def poll(self) -> list[str]:
        return _drain(self._words)

    def close(self) -> None:
        stream = getattr(self, "stream", None)
        if stream is not None:
            stream.stop()
            stream.close()
            self.stream = None
            self._blocks.put(None)
            self._thread.join(timeout=5)
            self.listener.close()


class Words(WordSource):
    """Several sources heard together."""

    def __init__(self, sources: list[WordSource]) -> None:
        self.sources = sources

    def poll(self) -> list[str]:
        return [w for s in self.sources for w in s.poll()]

    def close(self) -> None:
        for s in self.sources:
            s.close()
