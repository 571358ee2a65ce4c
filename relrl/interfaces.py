"""The two interfaces the control loop talks to: an environment and an actuator.

The Social Interactive Simulator, scripted episodes and a real camera implement
:class:`Environment`; the simulated and serial heads implement :class:`Actuator`. The
control loop (:mod:`relrl.loop`) only ever uses these methods, so an episode runs on the
simulator or on real devices by a flag.

An environment follows Gymnasium's API, with two relrl conventions:

* ``info["percepts"]`` (from ``reset`` and ``step``) is the list of perception facts of the
  new time unit, as terms (:mod:`relrl.terms`), e.g. ``("see", "face")``,
  ``("pose", "face", "frontal")``, ``("at", "toy", "left")``, ``("hear", "attention")``;
* ``step`` accepts a response term of the domain (e.g. ``("look", "left")``) as well as an
  element of its action space.
"""

from __future__ import annotations

import abc
from typing import Any

from relrl.terms import Term

__all__ = ["Environment", "Actuator", "NullActuator"]


class Environment(abc.ABC):
    """What the robot perceives and acts on, one time unit per step."""

    @abc.abstractmethod
    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        """Start an interaction; ``info["percepts"]`` holds the first percepts."""

    @abc.abstractmethod
    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Apply a response (term or action index) and advance one time unit."""

    def close(self) -> None:  # noqa: B027 - optional hook
        """Release resources. Safe to call twice."""


class Actuator(abc.ABC):
    """What turns a response into motion (a head, simulated or real)."""

    @abc.abstractmethod
    def emit(self, response: Term) -> None:
        """Carry out a response (play its motor script)."""

    def close(self) -> None:  # noqa: B027 - optional hook
        """Release the device. Safe to call twice."""


class NullActuator(Actuator):
    """An actuator that does nothing: the simulator moves its own robot."""

    def emit(self, response: Term) -> None:
        """Do nothing."""
