"""Errors the perception package raises on purpose (all are :class:`relrl.errors.UserError`)."""

from __future__ import annotations

from relrl.errors import UserError

__all__ = ["CameraError", "ImageError", "PerceptionError"]


class PerceptionError(UserError):
    """A bad perception input or parameter (the message shows the value and the fix)."""


class CameraError(PerceptionError):
    """A camera source that cannot be opened or read."""


class ImageError(PerceptionError):
    """An image file that is missing or cannot be decoded."""
