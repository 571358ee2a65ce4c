"""ART2 (Carpenter & Grossberg, 1987) for fruit colours, and naming by a caregiver.

:class:`ART2` is the analogue ART network: an F1 layer of six sublayers (``w, x, u, v, p, q``)
that normalises the input and suppresses noise (components below ``theta`` after
normalisation), an F2 layer of categories competing by bottom-up activation, and the orienting
subsystem that resets a category when the match vector ``r = (u + c p) / (e + |u| + |c p|)`` is
shorter than the vigilance ``rho``. The match is computed, as in the standard algorithm, from the
bottom-up pattern ``u`` and ``p = u + d t_J`` when the winner's template ``t_J`` first arrives.
Learning moves the chosen category's top-down and bottom-up weights toward ``u / (1 - d)``
(slow learning with rate ``alpha``, one update per presentation; a new category learns fast).
With ``c = 0.1, d = 0.9`` the vigilance ``rho = 0.97`` accepts patterns whose cosine with the
template is above about 0.85.

Features (:func:`colour_features`): ART2 normalises its input, so a plain (r, g, b) vector keeps
only chromaticity and loses nothing useful, but red, orange and yellow fruit differ by a few
tens of degrees of hue, and chromaticities crowd together under dim or tinted light. We code the
HSI hue of the fruit's area as a population of 12 channels tuned every 30 degrees (Gaussian,
sigma 20 degrees) scaled by saturation, plus one achromatic channel ``1 - saturation``. Hue and
saturation do not change with the light's brightness; a tint moves the hue by a few degrees,
well inside a tuning curve. All components are non-negative, as ART2's noise suppression needs.

:class:`FruitNamer` associates categories with the caregiver's words and counts the outcomes of
the paper's Table 1, which the paper names but does not define. Our definitions:

* ``unknown``: the presentation opens a new category, or one without a name; the robot says
  nothing and the caregiver's word names it;
* a category's name is its most-heard word; it is *confident* once that word has been heard
  ``confident_after`` times (3) and makes at least 75 % of its words. Otherwise a naming is a
  guess. Then ``correct_guess``/``incorrect_guess`` for a guess that is right/wrong and
  ``success``/``error`` for a confident naming that is right/wrong.

After every presentation the caregiver says the right word, which the category hears.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np

from perception.colour import ColourSummary

__all__ = ["ART2", "OUTCOMES", "ART2Params", "FruitNamer", "colour_features"]

#: the outcomes of Table 1, in the paper's order.
OUTCOMES: tuple[str, ...] = ("unknown", "correct_guess", "incorrect_guess", "error", "success")

_CENTRES = np.arange(0.0, 360.0, 30.0)
_SIGMA = 20.0


def colour_features(summary: ColourSummary) -> np.ndarray:
    """The ART2 input for a colour summary: 12 hue channels and one achromatic channel."""
    s = float(np.clip(summary.saturation, 0.0, 1.0))
    out = np.zeros(len(_CENTRES) + 1)
    if summary.hue is not None:
        d = np.abs((summary.hue - _CENTRES + 180.0) % 360.0 - 180.0)
        out[:-1] = s * np.exp(-d * d / (2 * _SIGMA * _SIGMA))
    out[-1] = 1.0 - s
    return out


@dataclass(frozen=True)
class ART2Params:
    """ART2 constants (names as in Carpenter & Grossberg, 1987).

    Attributes:
        a, b: feedback weights inside F1 (w = s + a u; v = f(x) + b f(q)).
        c, d: match weights; d is the F2 output of the winner (``c d / (1 - d) <= 1``).
        e: small constant that keeps norms finite.
        theta: noise suppression threshold of f.
        rho: vigilance (0..1); higher makes more, narrower categories.
        alpha: learning rate of the winning category (1 = fast learning).
        max_categories: F2 size.
    """

    a: float = 10.0
    b: float = 10.0
    c: float = 0.1
    d: float = 0.9
    e: float = 1e-6
    theta: float = 0.2
    rho: float = 0.97
    alpha: float = 0.5
    max_categories: int = 64


def _norm(v: np.ndarray, e: float) -> np.ndarray:
    return v / (e + np.linalg.norm(v))


class ART2:
    """An ART2 network over ``n`` non-negative inputs.

    Args:
        n: input size.
        params: network constants.
    """

    def __init__(self, n: int, params: ART2Params = ART2Params()) -> None:
        p = params
        if p.c * p.d / (1.0 - p.d) > 1.0:
            raise ValueError(f"ART2 needs c*d/(1-d) <= 1, got c={p.c}, d={p.d}")
        self.n = n
        self.params = p
        self.top_down = np.zeros((0, n))
        self.bottom_up = np.zeros((0, n))
        self._init_bu = 0.5 / ((1.0 - p.d) * np.sqrt(n))

    @property
    def categories(self) -> int:
        """Number of committed categories."""
        return len(self.top_down)

    def _f(self, x: np.ndarray) -> np.ndarray:
        return np.where(x >= self.params.theta, x, 0.0)

    def _f1(self, s: np.ndarray, t: np.ndarray | None, rounds: int = 3) -> dict[str, np.ndarray]:
        """Settle F1 for input ``s`` with top-down template ``t`` (None: no category)."""
        p = self.params
        u = np.zeros(self.n)
        q = np.zeros(self.n)
        layers: dict[str, np.ndarray] = {}
        for _ in range(rounds):
            w = s + p.a * u
            x = _norm(w, p.e)
            v = self._f(x) + p.b * self._f(q)
            u = _norm(v, p.e)
            pp = u if t is None else u + p.d * t
            q = _norm(pp, p.e)
            layers = {"u": u, "p": pp}
        return layers

    def present(self, s: np.ndarray, learn: bool = True) -> tuple[int, bool, float]:
        """Present one input.

        Args:
            s: input vector (non-negative).
            learn: update the winner's weights (and commit a new category if needed).

        Returns:
            ``(category, new, match)``: the resonating category (``-1`` when none resonates and
            ``learn`` is false or F2 is full), whether it was just committed, and ``|r|``.
        """
        p = self.params
        s = np.asarray(s, float)
        free = self._f1(s, None)
        u0 = free["u"]
        scores = self.bottom_up @ u0 if self.categories else np.zeros(0)
        uncommitted = self._init_bu * u0.sum()
        for j in np.argsort(-scores):
            if scores[j] < uncommitted:
                break
            # the orienting subsystem compares the bottom-up pattern u with the winner's
            # template as it first arrives at p (before F1 settles into the template)
            pp = u0 + p.d * self.top_down[j]
            r = (u0 + p.c * pp) / (p.e + np.linalg.norm(u0) + np.linalg.norm(p.c * pp))
            match = float(np.linalg.norm(r))
            if match >= p.rho:
                if learn:
                    self._learn(j, u0)
                return int(j), False, match
        if not learn or self.categories >= p.max_categories:
            return -1, False, 0.0
        self.top_down = np.vstack([self.top_down, np.zeros(self.n)])
        self.bottom_up = np.vstack([self.bottom_up, np.full(self.n, self._init_bu)])
        j = self.categories - 1
        self._learn(j, u0, fast=True)
        return j, True, 1.0

    def _learn(self, j: int, u: np.ndarray, fast: bool = False) -> None:
        p = self.params
        target = u / (1.0 - p.d)
        rate = 1.0 if fast else p.alpha
        self.top_down[j] += rate * (target - self.top_down[j])
        self.bottom_up[j] += rate * (target - self.bottom_up[j])


class FruitNamer:
    """ART2 colour categories with names learned from a caregiver (the paper's Table 1).

    Args:
        params: ART2 constants.
        confident_after: times a category must have heard its name before naming is confident.
    """

    def __init__(self, params: ART2Params = ART2Params(), confident_after: int = 3) -> None:
        self.net = ART2(len(_CENTRES) + 1, params)
        self.words: dict[int, Counter] = {}
        self.confident_after = confident_after
        self.counts: Counter = Counter({k: 0 for k in OUTCOMES})

    def name(self, features: np.ndarray) -> tuple[str | None, bool]:
        """What the robot would say for these features, without learning: (name, confident)."""
        j, _, _ = self.net.present(features, learn=False)
        return self._name_of(j)

    def _name_of(self, j: int) -> tuple[str | None, bool]:
        heard = self.words.get(j)
        if not heard:
            return None, False
        word, count = heard.most_common(1)[0]
        confident = count >= self.confident_after and count >= 0.75 * sum(heard.values())
        return word, confident

    def teach(self, features: np.ndarray, word: str) -> str:
        """One presentation: the robot names the fruit, then hears the caregiver's ``word``.

        Returns:
            The outcome, one of :data:`OUTCOMES`.
        """
        j, _, _ = self.net.present(features, learn=True)
        said, confident = self._name_of(j)
        if said is None:
            outcome = "unknown"
        elif confident:
            outcome = "success" if said == word else "error"
        else:
            outcome = "correct_guess" if said == word else "incorrect_guess"
        if j >= 0:
            self.words.setdefault(j, Counter())[word] += 1
        self.counts[outcome] += 1
        return outcome
