"""Sessions in robotics' formats: recorded as MCAP (Foxglove opens them, ROS 2 tools read the
camera and joints), served live to Foxglove, read back for replay, old folders migrated. See
``docs/recording.md``.

The public surface::

    CHANNELS                       # the channels of a session: topic, schema, encoding
    Recorder(foxglove=None)        # the session's side: hands each unit to the writer process
    Encoder()                      # a time unit as the messages of its channels
    McapFile(path)                 # an MCAP file being written (chunked, indexed, zstd)
    McapRecording(path)            # a recording read back (replay), strict about damage
    open_recording(path)           # what relrl replay reads: a .mcap, a folder
    migrate_folder(folder)         # an old recorded folder -> its session.mcap

Needs the ``mcap`` extra (``pip install 'relrl[mcap]'``; ``foxglove`` for the live server),
imported when a recording is written or read.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

__all__ = ["CHANNELS", "Encoder", "McapFile", "McapRecording", "Recorder", "migrate_folder",
           "open_recording"]

_WHERE = {"CHANNELS": "relrl.recording.channels", "Encoder": "relrl.recording.encoder",
          "McapFile": "relrl.recording.mcapfile", "McapRecording": "relrl.recording.reader",
          "open_recording": "relrl.recording.reader", "Recorder": "relrl.recording.recorder",
          "migrate_folder": "relrl.recording.migrate"}


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        return getattr(import_module(_WHERE[name]), name)
    raise AttributeError(f"module 'relrl.recording' has no attribute {name!r}")
