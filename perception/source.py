"""The interface every source of camera frames has (:mod:`perception.camera` opens them by
URL or name; :mod:`perception.bag` reads a ROS 2 bag)."""

from __future__ import annotations

import abc
from collections.abc import Iterator
from typing import Self

import numpy as np

__all__ = ["Camera"]


class Camera(abc.ABC):
    """Base class of camera sources: override :meth:`read` and, if needed, :meth:`_release`."""

    name = "camera"

    def __init__(self) -> None:
        self._closed = False

    @abc.abstractmethod
    def read(self) -> np.ndarray | None:
        """The next BGR frame, or ``None`` when the source has no more."""

    def _release(self) -> None:  # noqa: B027 - an optional hook
        """Free the device (called once by :meth:`close`)."""

    def close(self) -> None:
        """Release the source; safe to call twice."""
        if not self._closed:
            self._closed = True
            self._release()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __iter__(self) -> Iterator[np.ndarray]:
        while (frame := self.read()) is not None:
            yield frame
