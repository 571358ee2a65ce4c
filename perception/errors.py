"""Errors the perception package raises on purpose.

The perception package stands alone: it imports nothing from relrl. :class:`PerceptionError`
is the base of every error here; relrl's command line counts it among the errors a user can
cause (``relrl.errors.USER_ERRORS``): one line, exit status 2.
"""

from __future__ import annotations

__all__ = ["CameraError", "ImageError", "PerceptionError"]


class PerceptionError(Exception):
    """A bad perception input or parameter (the message shows the value and the fix)."""


class CameraError(PerceptionError):
    """A camera source that cannot be opened or read."""


class ImageError(PerceptionError):
    """An image file that is missing or cannot be decoded."""
