"""The live and replay web monitor of a robot session (``relrl run --monitor``,
``relrl replay DIR``): the camera frame with what perception found, percepts and working
memory, the necessities over time, reward, the response and why, the head's pose, CGI and
eye contacts, and the learned tree. See ``docs/monitor.md``.

Example::

    from relrl.monitor import Hub, start_live
    hub = Hub(rate=10)
    server = start_live(hub, "127.0.0.1:8765")   # prints nothing; server.url is the page
    ...                                           # RunOptions(monitor=hub)
    server.close()
"""

from __future__ import annotations

from typing import Any

from relrl.monitor.hub import Hub
from relrl.monitor.view import StepView

__all__ = ["Hub", "StepView", "start_live", "start_replay"]


def start_live(hub: Hub, address: str | None = None, token: str | None = None) -> Any:
    """Serve the live page over ``hub`` from a process of its own; returns the started
    :class:`~relrl.monitor.live.LiveServer`."""
    from relrl.monitor.live import LiveServer

    return LiveServer(hub, address, token=token).start()


def start_replay(folder: Any, address: str | None = None, token: str | None = None) -> Any:
    """Serve the replay page of a recorded session (a folder, an ``.mcap`` file, or one read
    already); returns the started server."""
    from relrl.monitor.replay import ReplaySource
    from relrl.monitor.server import MonitorServer
    from relrl.recording.reader import open_recording

    rec = folder if hasattr(folder, "rows") else open_recording(folder)
    return MonitorServer(ReplaySource(rec), address, token=token).start()
