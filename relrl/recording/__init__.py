"""Sessions in robotics' formats: recorded as MCAP (Foxglove opens them, ROS 2 tools read the
camera and joints), read back for replay, and old recorded folders migrated.

The public surface::

    CHANNELS                       # the channels of a session: topic, schema, encoding
    McapFile(path)                 # an MCAP file being written (chunked, indexed, zstd)
    SessionStream(sinks)           # a session's channels encoded off the control loop
    McapRecording(path)            # a recording read back (replay), strict about damage
    migrate_folder(folder)         # an old recorded folder -> its session.mcap

Needs the ``mcap`` extra (``pip install 'relrl[mcap]'``): the ``mcap`` and
``mcap-ros2-support`` packages, imported when a recording is written or read.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

__all__ = ["CHANNELS", "McapFile", "McapRecording", "SessionStream", "migrate_folder"]

_WHERE = {"CHANNELS": "relrl.recording.channels", "McapFile": "relrl.recording.mcapfile",
          "SessionStream": "relrl.recording.stream", "McapRecording": "relrl.recording.reader",
          "migrate_folder": "relrl.recording.migrate"}


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        return getattr(import_module(_WHERE[name]), name)
    raise AttributeError(f"module 'relrl.recording' has no attribute {name!r}")
