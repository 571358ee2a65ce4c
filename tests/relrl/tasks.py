"""Small environments for the engine's tests."""

from __future__ import annotations

from typing import Any

import numpy as np

from relrl.interfaces import Environment
from relrl.terms import Term

BEST = {"light": "a", "dark": "c"}


class LightDark(Environment):
    """Two states drawn at random each step; the right response is rewarded next step."""

    def __init__(self) -> None:
        self.rng = np.random.default_rng(0)
        self.state = "light"

    def _percepts(self, fed: bool) -> list[Term]:
        percepts: list[Term] = [("see", self.state)]
        if fed:
            percepts.append(("smell", "food"))
        return percepts

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.state = "light"
        return None, {"percepts": self._percepts(False)}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        fed = action == BEST[self.state]
        self.state = "light" if self.rng.random() < 0.5 else "dark"
        return None, 10.0 if fed else -1.0, False, False, {"percepts": self._percepts(fed),
                                                          "fed": fed}


class GazeTask(Environment):
    """A caregiver looks at one of ``places`` (drawn each step); looking there is rewarded
    at the next step (``smell(treat)``). The domain is tests/data/tg_gaze.pl."""

    def __init__(self, places: tuple[str, ...] = ("p1", "p2", "p3", "p4")) -> None:
        self.places = places
        self.rng = np.random.default_rng(0)
        self.gaze = places[0]

    def _percepts(self, fed: bool) -> list[Term]:
        percepts: list[Term] = [("see", "face"), ("pose", "face", self.gaze)]
        if fed:
            percepts.append(("smell", "treat"))
        return percepts

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.gaze = self.places[int(self.rng.integers(len(self.places)))]
        return None, {"percepts": self._percepts(False)}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        fed = action == ("look", self.gaze)
        self.gaze = self.places[int(self.rng.integers(len(self.places)))]
        return None, 10.0 if fed else -1.0, False, False, {"percepts": self._percepts(fed),
                                                          "fed": fed}
