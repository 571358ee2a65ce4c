"""Errors of the Social Interactive Simulator (all are :class:`relrl.errors.UserError`)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

from relrl.errors import ConfigError, UserError

__all__ = [
    "CaregiverConfigError",
    "InvalidResponse",
    "SimError",
    "UnknownCaregiver",
    "did_you_mean",
]


class SimError(UserError):
    """Base class of the simulator's errors."""


class InvalidResponse(SimError, ValueError):
    """``step`` got something that is neither an action index nor a known response."""


class CaregiverConfigError(SimError, ConfigError):
    """A caregiver parameter has a bad value."""


class UnknownCaregiver(CaregiverConfigError, KeyError):
    """No caregiver model is registered under this name."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0])


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """Return ``"; did you mean 'x'?"`` for the closest choice, or ``""``."""
    close = difflib.get_close_matches(word, list(choices), n=1)
    return f"; did you mean {close[0]!r}?" if close else ""
