"""Frames recorded by a relrl session, read back in order (``recording://DIR``).

A recorded session folder (``relrl run ... --out DIR --record``) holds ``frames.jsonl`` (one
line per frame: index, time unit, file, where the head looked) and the JPEG files under
``frames/``. :class:`RecordedCamera` reads them in that order, so the perception pipeline can
be run again on what the robot saw (record with ``--record-rate 0`` to have every time unit).
``open_camera(DIR)`` picks this source for a folder with a ``frames.jsonl``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from perception.camera import Camera, read_image
from perception.errors import CameraError

__all__ = ["RecordedCamera"]


class RecordedCamera(Camera):
    """The frames of a recorded session, in recorded order.

    Args:
        folder: the session folder (with ``frames.jsonl``).

    Raises:
        CameraError: no such folder, or no frame index in it.
    """

    def __init__(self, folder: str | Path) -> None:
        super().__init__()
        self.folder = Path(folder)
        index = self.folder / "frames.jsonl"
        if not index.is_file():
            raise CameraError(f"{folder}: not a recorded session with frames (no "
                              "frames.jsonl); record with relrl run --out DIR --record")
        self.entries = []
        for n, line in enumerate(index.read_text(encoding="utf-8").splitlines(), 1):
            if not line.strip():
                continue
            try:
                self.entries.append(json.loads(line))
            except json.JSONDecodeError:
                raise CameraError(f"{index}:{n}: not a JSON line") from None
        if not self.entries:
            raise CameraError(f"{index}: no frames were recorded")
        self.name = f"recording {folder}"
        self._next = 0

    @property
    def position(self) -> int:
        """How many frames have been read."""
        return self._next

    def read(self) -> np.ndarray | None:
        if self._closed or self._next >= len(self.entries):
            return None
        entry = self.entries[self._next]
        self._next += 1
        return read_image(self.folder / entry["file"])
