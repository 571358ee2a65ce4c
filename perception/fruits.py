"""The fruit-naming session of experiment 2 on synthetic frames (the paper's Table 1).

A caregiver shows apples, lemons and oranges one at a time at random places under changing
light; the robot looks at the fruit, the perception pipeline finds the salient area and its
colour, :class:`perception.art2.FruitNamer` names it (or not) and hears the caregiver's word.
Run ``python -m perception.fruits`` for the table.
"""

from __future__ import annotations

import argparse

import numpy as np

from perception.art2 import OUTCOMES, ART2Params, FruitNamer, colour_features
from perception.render import SceneView, render
from perception.vocab import OBJECT_PLACES

__all__ = ["FRUITS", "fruit_session", "table1"]

FRUITS: tuple[str, ...] = ("apple", "lemon", "orange")


def fruit_session(presentations: int = 60, seed: int = 0, light: tuple[float, float] = (0.6, 1.3),
                  size: tuple[int, int] = (320, 240),
                  params: ART2Params | None = None) -> dict[str, int]:
    """One execution: ``presentations`` fruits; returns outcome counts (plus ``missed``).

    ``missed`` counts presentations where perception found no salient area.
    """
    from perception.pipeline import Perceiver

    rng = np.random.default_rng(seed)
    namer = FruitNamer(params or ART2Params())
    perceiver = Perceiver()
    missed = 0
    for _ in range(presentations):
        fruit = FRUITS[int(rng.integers(len(FRUITS)))]
        place = OBJECT_PLACES[int(rng.integers(len(OBJECT_PLACES)))]
        view = SceneView(place, None, {place: fruit}, float(rng.uniform(*light)),
                         int(rng.integers(2**31)))
        percept = perceiver.analyse(render(view, size), looking_at=place)
        if percept.colour is None:
            missed += 1
            continue
        namer.teach(colour_features(percept.colour), fruit)
    counts = {k: int(namer.counts[k]) for k in OUTCOMES}
    counts["missed"] = missed
    counts["categories"] = namer.net.categories
    return counts


def table1(executions: int = 5, presentations: int = 60, seed: int = 0,
           light: tuple[float, float] = (0.6, 1.3)) -> dict[str, object]:
    """Several executions; per-outcome counts and rates (percent, mean and std)."""
    runs = [fruit_session(presentations, seed + k, light) for k in range(executions)]
    rates = {}
    for k in OUTCOMES:
        r = np.array([100.0 * run[k] / presentations for run in runs])
        rates[k] = (round(float(r.mean()), 2), round(float(r.std()), 2))
    return {"runs": runs, "rates": rates}


def main(argv: list[str] | None = None) -> int:
    """Print Table 1 for the synthetic fruit session."""
    parser = argparse.ArgumentParser(description="Table 1 on synthetic fruits")
    parser.add_argument("--executions", type=int, default=5)
    parser.add_argument("--presentations", type=int, default=60)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    result = table1(args.executions, args.presentations, args.seed)
    for i, run in enumerate(result["runs"]):
        print(f"execution {i}: {run}")
    for k, (mean, std) in result["rates"].items():
        print(f"{k:16s} {mean:6.2f} +- {std:.2f} %")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
