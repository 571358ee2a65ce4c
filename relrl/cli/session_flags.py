"""The session flags of ``relrl run``: monitor, recording, microphone, audio file, log file.

Kept apart from :mod:`relrl.cli.run` so the run command stays a thin front: this module
declares the flags, checks them, starts what they ask for (the web monitor, the word
sources, the log file) and stops it again.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import sys
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from relrl.errors import ConfigError

__all__ = ["add_session_arguments", "session_options"]


def add_session_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare ``--monitor``, ``--record``, ``--mic``, ``--audio`` and their options."""
    g = parser.add_argument_group("watch, record, listen")
    g.add_argument("--monitor", nargs="?", const="", default=None, metavar="HOST:PORT",
                   help="serve a live web page of the session (default 127.0.0.1 and a free "
                        "port, printed at start; off localhost a token is required)")
    g.add_argument("--monitor-rate", type=float, default=10.0, metavar="HZ",
                   help="views and frames sent to the browser (and to Foxglove, when not "
                        "recording) per second, at most (10)")
    g.add_argument("--monitor-hold", action="store_true",
                   help="keep the page up after the session ends, until Ctrl-C")
    g.add_argument("--foxglove", nargs="?", const="", default=None, metavar="HOST:PORT",
                   help="serve the session live to Foxglove over its WebSocket protocol "
                        "(default 127.0.0.1:8765; off localhost a token is required; needs "
                        "the mcap and foxglove extras)")
    g.add_argument("--foxglove-origin", action="append", default=[], metavar="ORIGIN",
                   help="let the pages of this web origin connect to --foxglove (a browser's "
                        "connection from any other page is refused), e.g. "
                        "https://app.foxglove.dev for Foxglove's web app; repeatable")
    g.add_argument("--record", action="store_true",
                   help="record the session into --out DIR/session.mcap (MCAP: Foxglove "
                        "opens it, `relrl replay` scrubs it; needs the mcap extra)")
    g.add_argument("--record-rate", type=float, default=10.0, metavar="HZ",
                   help="recorded frames per second, at most (10; 0: every time unit, so "
                        "`--camera DIR` can perceive them again)")
    g.add_argument("--record-quality", type=int, default=85, metavar="Q",
                   help="JPEG quality of recorded frames, 1..100 (85)")
    g.add_argument("--mic", nargs="?", const="default", default=None, metavar="DEVICE",
                   help="hear the caregiver through a microphone (default input device, or "
                        "an index or name from `python -m sounddevice`)")
    g.add_argument("--audio", default=None, metavar="FILE.wav",
                   help="hear a recorded WAV file, --audio-seconds per time unit")
    g.add_argument("--audio-seconds", type=float, default=0.5, metavar="S",
                   help="seconds of --audio heard per time unit (0.5)")


class _Closing:
    def __init__(self, fn: Any) -> None:
        self.close = fn


@dataclass
class Session:
    """What the flags started; :meth:`hold` keeps the monitor up after the run."""

    opts: Any
    server: Any = None
    closers: list[Any] = field(default_factory=list)
    hold_after: bool = False

    def log_to(self, path: Any) -> None:
        """Also log to ``path`` (the session's ``run.log``) until the session ends."""
        import logging

        from relrl import log

        handler = log.add_file(path)
        self.closers.append(_Closing(lambda: log.remove_file(handler)))
        logging.getLogger("relrl.run").debug("session started: %s", " ".join(sys.argv))

    def hold(self) -> None:
        """With ``--monitor-hold``: serve until Ctrl-C."""
        if self.server is None or not self.hold_after:
            return
        print(f"the monitor stays up at {self.server.url} ; Ctrl-C ends it", flush=True)
        try:
            while True:
                time.sleep(0.5)
        except KeyboardInterrupt:
            pass


def _vocabulary(episode: Any) -> list[str]:
    return sorted({episode.word_for(k) for k in episode.fruits} | {"attention"})


def _words(args: argparse.Namespace, episode: Any, closers: list[Any]) -> Any:
    from relrl.listen import AudioFileWords, MicWords, TypedWords, Words

    sources = []
    if args.live:
        sources.append(TypedWords())
        print("live session: type words (e.g. apple, attention) and Enter; Ctrl-C stops",
              flush=True)
    if args.audio is not None:
        sources.append(AudioFileWords(args.audio, _vocabulary(episode), args.audio_seconds))
    if args.mic is not None:
        sources.append(MicWords(_vocabulary(episode),
                                None if args.mic == "default" else args.mic))
    closers.extend(sources)
    if not sources:
        return None
    return sources[0] if len(sources) == 1 else Words(sources)


def _check(args: argparse.Namespace) -> None:
    if not args.monitor_rate > 0:
        raise ConfigError(f"--monitor-rate must be positive, not {args.monitor_rate}")
    if args.record and not args.out:
        raise ConfigError("--record needs --out DIR (the recording goes there)")
    if not (math.isfinite(args.record_rate) and args.record_rate >= 0):
        raise ConfigError(f"--record-rate must be a number of frames per second >= 0 (0: "
                          f"every time unit), not {args.record_rate}")
    if not 1 <= args.record_quality <= 100:
        raise ConfigError(f"--record-quality must be in 1..100, not {args.record_quality}")
    if args.monitor_hold and args.monitor is None:
        raise ConfigError("--monitor-hold needs --monitor")
    if args.foxglove_origin:
        from relrl.monitor.server import parse_origin

        if args.foxglove is None:
            raise ConfigError("--foxglove-origin needs --foxglove")
        for origin in args.foxglove_origin:
            parse_origin(origin)
    if args.record or args.foxglove is not None:
        missing = [name for name in ("mcap", "mcap_ros2", "foxglove")
                   + (("websockets",) if args.foxglove is not None else ())
                   if importlib.util.find_spec(name) is None]
        if missing:
            extras = "mcap,foxglove" if args.foxglove is not None else "mcap"
            raise ConfigError(f"{'--record' if args.record else '--foxglove'} needs "
                              f"{', '.join(missing)}: pip install 'relrl[{extras}]'")


@contextmanager
def session_options(args: argparse.Namespace, episode: Any, opts: Any):
    """Start what the flags ask for around a run; yields a :class:`Session` whose ``opts``
    carry the monitor, the recording settings and the word sources."""
    _check(args)
    session = Session(opts, hold_after=args.monitor_hold)
    try:
        opts.record = args.record
        opts.record_rate = args.record_rate
        opts.record_quality = args.record_quality
        opts.words = _words(args, episode, session.closers)
        if args.monitor is not None:
            from relrl.monitor import Hub, start_live

            opts.monitor = Hub(args.monitor_rate)
            session.server = start_live(opts.monitor, args.monitor or None)
            session.closers.append(session.server)
            note = " (token required: not bound to localhost)" if session.server.token else ""
            print(f"monitor: {session.server.url}{note}", flush=True)
        if args.foxglove is not None:
            from relrl.recording.recorder import Recorder

            opts.recorder = Recorder(foxglove=args.foxglove,
                                     origins=tuple(args.foxglove_origin))
            opts.live_rate = args.monitor_rate
            session.closers.append(opts.recorder)
            note = " (token required: not bound to localhost)" if opts.recorder.token else ""
            web = "" if args.foxglove_origin else \
                "; its web app needs --foxglove-origin https://app.foxglove.dev"
            print(f"foxglove: {opts.recorder.url}{note} (in Foxglove: Open connection, "
                  f"Foxglove WebSocket{web})", flush=True)
        yield session
    finally:
        for thing in reversed(session.closers):
            thing.close()
