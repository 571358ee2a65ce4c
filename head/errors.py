"""Errors raised by the head package, all in one place.

The head package stands alone: it imports nothing from relrl. :class:`HeadError` is the base
of every error here; each says what was wrong and how to fix it. relrl's command line counts
it among the errors a user can cause (``relrl.errors.USER_ERRORS``): one line, exit status 2.
"""

from __future__ import annotations

__all__ = [
    "CalibrationError",
    "HeadClosed",
    "HeadError",
    "HeadTimeout",
    "PortLost",
    "PortUnavailable",
    "ProtocolError",
    "UnknownDirection",
    "UnknownProtocol",
    "UnknownResponse",
    "UnknownServo",
]


class HeadError(Exception):
    """Base class of every error of the robotic head."""


class CalibrationError(HeadError, ValueError):
    """A calibration (or motor script) file does not validate; names the file and the key."""


class UnknownProtocol(HeadError, ValueError):
    """No servo-controller protocol is registered under that name."""


class UnknownDirection(HeadError):
    """A direction name that the calibration does not define."""


class UnknownResponse(HeadError):
    """A response with no motor script in the calibration."""


class UnknownServo(HeadError):
    """A pose names a servo that the calibration does not define, or has a bad value."""


class PortUnavailable(HeadError):
    """The serial port could not be opened (missing device, busy, no permission)."""


class PortLost(HeadError):
    """The serial port failed while in use (cable pulled, controller lost power)."""


class HeadTimeout(HeadError):
    """The controller did not answer in time, or a move did not finish in time."""


class ProtocolError(HeadError):
    """The controller answered something the protocol does not allow."""


class HeadClosed(HeadError):
    """The head was used after ``close()``; call ``reopen()`` first."""
