"""The metrics on hand-made traces, with hand-counted answers."""

from __future__ import annotations

import math

import pytest

from relrl.sim.metrics import (
    GazeMetrics,
    StepRecord,
    cgi,
    eye_contacts,
    mutual_gaze_events,
    summarize,
)


def trace(*steps: tuple) -> list[StepRecord]:
    """Records from (focus, gaze) or (focus, gaze, opportunity) tuples; 'C' is centre."""
    out = []
    for t, step in enumerate(steps):
        focus, gaze, *rest = step
        focus = "centre" if focus == "C" else focus
        out.append(StepRecord(t, focus, gaze, opportunity=rest[0] if rest else 0))
    return out


F = "frontal"


def test_mutual_gaze_counts_one_event_per_streak_of_three() -> None:
    # streaks on the frontal face: 4 (event), 2 (none), 3 (event), 1 (none)
    tr = trace(("C", F), ("C", F), ("C", F), ("C", F), ("left", F),
               ("C", F), ("C", F), ("down", F),
               ("C", F), ("C", F), ("C", F), ("right", F), ("C", F))
    assert mutual_gaze_events(tr) == 2


def test_mutual_gaze_needs_the_frontal_face() -> None:
    # the caregiver turns away in the middle: two streaks of 2, no event
    tr = trace(("C", F), ("C", F), ("C", "left"), ("C", F), ("C", F))
    assert mutual_gaze_events(tr) == 0
    assert mutual_gaze_events(tr, hold=2) == 2


def test_cgi_counts_only_shifts_from_the_face_while_the_caregiver_looks_somewhere() -> None:
    tr = trace(
        ("C", "left"), ("left", "left"),          # shift to the gazed place: correct
        ("C", "down"), ("right", "down"),         # shift elsewhere: wrong
        ("C", F), ("left", F),                    # caregiver looks at the robot: not counted
        ("left", "left"), ("down", "left"),       # not from the face: not counted
        ("C", "right"), ("C", "right"),           # stays on the face: not a shift
        ("C", "right_down"), ("right_down", F),   # correct: the gaze before the shift counts
    )
    result = cgi(tr)
    assert (result.correct, result.shifts) == (2, 3)
    assert result.value == pytest.approx(2 / 3)


def test_cgi_is_nan_without_shifts() -> None:
    result = cgi(trace(("C", F), ("C", F), ("left", F)))
    assert result.shifts == 0 and math.isnan(result.value)


def test_eye_contacts_per_opportunity() -> None:
    tr = trace(
        ("C", F, 0), ("C", F, 0), ("C", F, 0),             # opportunity 0: established
        ("left", "left", 0), ("C", "left", 0),             # (its trial, same number)
        ("left", F, 1), ("C", F, 1), ("C", F, 1), ("down", F, 1),  # 1: only 2 in a row
        ("C", F, 2), ("C", F, 2), ("left", F, 2), ("C", F, 2),     # 2: missed
        ("C", F, 3), ("C", F, 3),                                  # 3: still open: left out
    )
    result = eye_contacts(tr)
    assert result.per_opportunity == (True, False, False)
    assert (result.established, result.opportunities) == (1, 3)
    assert eye_contacts(tr, first=1).established == 1
    assert eye_contacts(tr, first=1).opportunities == 1


def test_eye_contact_streak_does_not_carry_across_opportunities() -> None:
    tr = trace(("C", F, 0), ("C", F, 0), ("C", F, 1), ("left", F, 2))
    assert eye_contacts(tr).per_opportunity == (False, False)


def test_open_opportunity_counts_once_established() -> None:
    tr = trace(("C", F, 0), ("C", F, 0), ("C", F, 0))
    assert eye_contacts(tr).per_opportunity == (True,)


def test_streaming_equals_batch() -> None:
    tr = trace(("C", F, 0), ("C", F, 0), ("C", F, 0), ("C", "left", 0), ("left", "left", 0),
               ("left", F, 1), ("C", F, 1))
    m = GazeMetrics()
    for rec in tr:
        m.add(rec)
    assert m.cgi() == cgi(tr)
    assert m.mutual_gaze_events == mutual_gaze_events(tr) == 1
    assert m.eye_contacts() == eye_contacts(tr)
    assert summarize(tr) == {"cgi": 1.0, "cgi_literal": 1.0, "correct_shifts": 1,
                             "shifts": 1, "all_shifts": 1, "mutual_gaze_events": 1,
                             "eye_contacts": 1, "opportunities": 1}


def test_hold_must_be_positive() -> None:
    with pytest.raises(ValueError, match="hold=0"):
        GazeMetrics(hold=0)


# ---- Eq. 5 read literally beside relrl's reading ------------------------------------------------

def test_literal_cgi_counts_shifts_while_the_caregiver_looks_at_the_robot() -> None:
    # 1: leaves the face while the caregiver looks at the robot (literal: a wrong shift)
    # 2: waits, sees the caregiver look left, follows (correct in both)
    # 3: sees right, goes down (wrong in both)
    tr = trace(("C", F), ("down", F),
               ("C", F), ("C", "left"), ("left", "left"),
               ("C", F), ("C", "right"), ("down", "right"))
    m = GazeMetrics().extend(tr)
    assert (m.cgi().correct, m.cgi().shifts) == (1, 2)
    assert (m.cgi_literal().correct, m.cgi_literal().shifts) == (1, 3)
    assert m.cgi().value == 0.5 and m.cgi_literal().value == pytest.approx(1 / 3)


def test_literal_cgi_equals_relrls_when_the_robot_never_leaves_a_frontal_face() -> None:
    tr = trace(("C", F), ("C", F), ("C", "down"), ("down", "down"), ("C", F), ("C", "left"),
               ("right", "left"), ("C", F))
    m = GazeMetrics().extend(tr)
    assert m.cgi() == m.cgi_literal() and m.cgi().value == 0.5


def test_a_robot_that_never_leaves_the_face_has_no_cgi_in_either_reading() -> None:
    m = GazeMetrics().extend(trace(("C", F), ("C", "left"), ("C", F)))
    assert math.isnan(m.cgi().value) and math.isnan(m.cgi_literal().value)
    assert m.summary()["all_shifts"] == 0
