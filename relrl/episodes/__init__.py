"""Scripted interaction episodes (``relrl run``): scripts, the scripted world, running them.

Example::

    from relrl.episodes import load_episode, run_episode, RunOptions
    ep = load_episode("examples/episodes/hello.toml")
    summary = run_episode(ep, RunOptions(out=Path("runs/hello")))

See ``docs/episodes.md``.
"""

from relrl.episodes.script import Episode, EpisodeError, Event, Phase, load_episode, parse_episode
from relrl.episodes.session import RunOptions, StopRequest, run_episode
from relrl.episodes.world import EpisodeWorld, ProtocolCaregiver

__all__ = [
    # scripts
    "Episode",
    "EpisodeError",
    # the world
    "EpisodeWorld",
    "Event",
    "Phase",
    "ProtocolCaregiver",
    # running
    "RunOptions",
    "StopRequest",
    "load_episode",
    "parse_episode",
    "run_episode",
]
