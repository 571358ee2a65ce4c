"""ART2 clustering and naming (Table 1 outcomes)."""

import numpy as np
import pytest

from perception.art2 import ART2, OUTCOMES, ART2Params, FruitNamer, colour_features
from perception.colour import ColourSummary


def _colour(hue, sat=0.7):
    return colour_features(ColourSummary(0, 0, 0, hue, sat, 0.5, None))


def test_same_input_resonates_with_its_category():
    net = ART2(13)
    j, new, _ = net.present(_colour(0))
    assert new and j == 0
    j2, new2, match = net.present(_colour(3))
    assert (j2, new2) == (0, False) and match >= net.params.rho


def test_distinct_hues_get_distinct_categories():
    net = ART2(13)
    cats = {net.present(_colour(h))[0] for h in (2, 28, 55)}
    assert len(cats) == 3


def test_low_vigilance_merges_categories():
    net = ART2(13, ART2Params(rho=0.5))
    cats = {net.present(_colour(h))[0] for h in (2, 28)}
    assert len(cats) == 1


def test_bad_constants_are_rejected():
    with pytest.raises(ValueError):
        ART2(4, ART2Params(c=0.5, d=0.9))


def test_brightness_does_not_change_features():
    a = colour_features(ColourSummary(0, 0, 0, 30.0, 0.8, 0.2, None))
    b = colour_features(ColourSummary(0, 0, 0, 30.0, 0.8, 0.9, None))
    assert np.allclose(a, b)


def test_namer_outcomes_follow_the_protocol():
    namer = FruitNamer(confident_after=2)
    apple, lemon = _colour(2), _colour(55)
    assert namer.teach(apple, "apple") == "unknown"
    assert namer.teach(apple, "apple") == "correct_guess"
    assert namer.teach(apple, "apple") == "success"
    assert namer.teach(lemon, "lemon") == "unknown"
    assert namer.teach(apple, "cherry") == "error"  # a confident but wrong name
    assert sum(namer.counts.values()) == 5 and set(namer.counts) == set(OUTCOMES)


def test_incorrect_guess():
    namer = FruitNamer(confident_after=3)
    namer.teach(_colour(2), "apple")
    assert namer.teach(_colour(2), "tomato") == "incorrect_guess"


@pytest.mark.slow
def test_synthetic_fruit_session_mostly_succeeds():
    from perception.fruits import fruit_session

    counts = fruit_session(presentations=30, seed=1)
    assert counts["missed"] == 0
    assert counts["unknown"] >= 3  # each fruit is new once
    assert counts["success"] + counts["correct_guess"] >= 22
    assert counts["error"] + counts["incorrect_guess"] <= 2
    assert fruit_session(presentations=30, seed=1) == counts  # same seed, same numbers
