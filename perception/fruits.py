"""The fruit-naming session of experiment 2 on synthetic frames (the paper's Table 1).

A caregiver shows apples, lemons and oranges one at a time at random places; the robot looks at
the fruit, the perception pipeline finds the salient area and its colour,
:class:`perception.art2.FruitNamer` names it (or not) and hears the caregiver's word. With
``variation`` (the default) every presentation is a different fruit of its kind, held
differently, under the session's light as a webcam's white balance and exposure leave it, with
blur and noise (:mod:`perception.appearance`); without it, plain drawings under a light gain.
Run ``python -m perception.fruits`` for the table and the confusions.
"""

from __future__ import annotations

import argparse
from collections import Counter

import numpy as np

from perception.appearance import Appearance, Variation
from perception.art2 import OUTCOMES, ART2Params, FruitNamer, colour_features
from perception.render import SceneView, render
from perception.vocabulary import OBJECT_PLACES

__all__ = ["FRUITS", "confusion_table", "fruit_session", "table1"]

FRUITS: tuple[str, ...] = ("apple", "lemon", "orange")


def fruit_session(presentations: int = 60, seed: int = 0, light: tuple[float, float] = (0.6, 1.3),
                  size: tuple[int, int] = (320, 240), params: ART2Params | None = None,
                  variation: Variation | None = None, fruits: tuple[str, ...] = FRUITS
                  ) -> dict[str, object]:
    """One execution: ``presentations`` fruits; returns the outcome counts, ``missed``
    (presentations where perception found no salient area), ``categories`` and ``said``
    (``(fruit, name said or None)`` per taught presentation).

    Args:
        presentations: fruits shown.
        seed: seeds everything drawn (fruit, place, look, light).
        light: range of the light gain of each frame (plain drawings; with ``variation`` its
            exposure range applies).
        size: frame size.
        params: ART2 constants.
        variation: appearance variation (``None``: plain drawings).
        fruits: the kinds shown; each is named by its kind.
    """
    from perception.pipeline import Perceiver

    rng = np.random.default_rng(seed)
    namer = FruitNamer(params or ART2Params())
    perceiver = Perceiver()
    room = variation.session_light(rng) if variation is not None else 0.0
    missed = 0
    said: list[tuple[str, str | None]] = []
    for _ in range(presentations):
        fruit = fruits[int(rng.integers(len(fruits)))]
        place = OBJECT_PLACES[int(rng.integers(len(OBJECT_PLACES)))]
        app, gain = None, 1.0
        if variation is not None:
            app = Appearance(variation.exposed(rng, variation.light(rng, room)),
                             variation.optics(rng), {place: variation.fruit(rng, fruit)})
        else:
            gain = float(rng.uniform(*light))
        view = SceneView(place, None, {place: fruit}, gain, int(rng.integers(2**31)), app)
        percept = perceiver.analyse(render(view, size), looking_at=place)
        if percept.colour is None:
            missed += 1
            continue
        features = colour_features(percept.colour)
        said.append((fruit, namer.name(features)[0]))
        namer.teach(features, fruit)
    return {**{k: int(namer.counts[k]) for k in OUTCOMES}, "missed": missed,
            "categories": namer.net.categories, "said": said}


def confusion_table(said: list[tuple[str, str | None]]) -> dict[str, dict[str, int]]:
    """Per fruit shown, how often the robot said each name (``None``: said nothing)."""
    table: dict[str, Counter] = {}
    for fruit, name in said:
        table.setdefault(fruit, Counter())[str(name) if name is not None else "nothing"] += 1
    return {fruit: dict(sorted(c.items())) for fruit, c in sorted(table.items())}


def table1(executions: int = 5, presentations: int = 60, seed: int = 0,
           light: tuple[float, float] = (0.6, 1.3), variation: Variation | None = None
           ) -> dict[str, object]:
    """Several executions; per-outcome rates (percent of taught presentations, mean and sd)
    and the confusions over all of them."""
    runs = [fruit_session(presentations, seed + k, light, variation=variation)
            for k in range(executions)]
    rates = {}
    for k in OUTCOMES:
        r = np.array([100.0 * run[k] / max(1, presentations - run["missed"]) for run in runs])
        rates[k] = (round(float(r.mean()), 2), round(float(r.std()), 2))
    said = [pair for run in runs for pair in run["said"]]
    return {"runs": runs, "rates": rates, "confusion": confusion_table(said)}


def main(argv: list[str] | None = None) -> int:
    """Print Table 1 and the confusions for the synthetic fruit session."""
    parser = argparse.ArgumentParser(description="Table 1 on synthetic fruits")
    parser.add_argument("--executions", type=int, default=5)
    parser.add_argument("--presentations", type=int, default=60)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--plain", action="store_true",
                        help="plain drawings under a light gain (no appearance variation)")
    args = parser.parse_args(argv)
    result = table1(args.executions, args.presentations, args.seed,
                    variation=None if args.plain else Variation())
    for i, run in enumerate(result["runs"]):
        shown = {k: v for k, v in run.items() if k != "said"}
        print(f"execution {i}: {shown}")
    for k, (mean, std) in result["rates"].items():
        print(f"{k:16s} {mean:6.2f} +- {std:.2f} %")
    print("confusions (fruit shown: name said):")
    for fruit, row in result["confusion"].items():
        print(f"  {fruit:8s} {row}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
