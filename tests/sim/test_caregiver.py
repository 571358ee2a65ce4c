"""The caregiver models: parameters, registry and the paper's protocol, time unit by time unit."""

from __future__ import annotations

import itertools
from collections import Counter

import numpy as np
import pytest

from relrl.errors import ConfigError, UserError
from relrl.sim.caregiver import (
    ATTEND,
    ENGAGE,
    EVALUATION_SEQUENCE,
    PRESENT,
    CaregiverParams,
    ProtocolCaregiver,
    caregiver_names,
    make_caregiver,
    register_caregiver,
)
from relrl.sim.errors import CaregiverConfigError, UnknownCaregiver
from relrl.sim.places import PLACES, TOY_PLACES, place_index

C = 0  # the caregiver's face


def start(params: CaregiverParams | None = None, seed: int = 0, focus: int = 1
          ) -> ProtocolCaregiver:
    cg = ProtocolCaregiver(params or CaregiverParams())
    cg.reset(np.random.default_rng(seed), focus)
    return cg


def contact(cg: ProtocolCaregiver) -> None:
    """Look at the face until eye contact is made."""
    for _ in range(cg.params.contact_hold):
        cg.update(C)
    assert cg.contact


# ---- parameters and registry -----------------------------------------------------------------

@pytest.mark.parametrize(("overrides", "message"), [
    ({"n_toys": 0}, "n_toys=0"),
    ({"n_toys": 6}, "n_toys=6"),
    ({"placement": {"lefft": 1.0}}, "did you mean 'left'"),
    ({"placement": {"left": -1.0}}, "must be a number >= 0"),
    ({"placement": {"left": 0.0}}, "at least one place"),
    ({"reliability": 1.5}, "reliability=1.5"),
    ({"latency": -1}, "latency=-1"),
    ({"timeout": 0}, "timeout=0"),
    ({"contact_timeout": 2}, "contact_timeout=2"),
    ({"target_sequence": ("left", "upp")}, "unknown place 'upp'"),
    ({"target_sequence": ()}, "non-empty"),
    ({"toy_colours": ("red", "")}, "toy_colours"),
])
def test_bad_parameters_are_user_errors_naming_the_value(overrides: dict, message: str) -> None:
    with pytest.raises(CaregiverConfigError, match=message) as err:
        CaregiverParams().replace(**overrides)
    assert isinstance(err.value, ConfigError) and isinstance(err.value, UserError)


def test_unknown_parameter_suggests_the_closest() -> None:
    with pytest.raises(CaregiverConfigError, match="did you mean 'reliability'"):
        CaregiverParams().replace(reliabilty=0.5)


def test_placement_is_completed_and_params_are_json_ready() -> None:
    p = CaregiverParams(placement={"left": 2})
    assert p.placement == {"left": 2.0, "left_down": 0.0, "down": 0.0, "right_down": 0.0,
                           "right": 0.0}
    d = p.for_evaluation().to_dict()
    assert d["target_sequence"] == list(EVALUATION_SEQUENCE) and d["n_toys"] == 2


def test_registry_lookup_and_did_you_mean() -> None:
    assert {"paper", "unreliable", "random", "one_toy"} <= set(caregiver_names())
    assert make_caregiver("unreliable").params.reliability == 0.5
    assert make_caregiver("paper", {"timeout": 9}).params.timeout == 9
    with pytest.raises(UnknownCaregiver, match="did you mean 'paper'"):
        make_caregiver("papper")


def test_register_a_new_model() -> None:
    register_caregiver("test_patient", ProtocolCaregiver, CaregiverParams(timeout=50), "test")
    assert make_caregiver("test_patient").params.timeout == 50


def test_evaluation_sequence_is_balanced_without_repeats() -> None:
    assert Counter(EVALUATION_SEQUENCE) == {p: 4 for p in TOY_PLACES}
    assert all(a != b for a, b in itertools.pairwise(EVALUATION_SEQUENCE))


# ---- the protocol, time unit by time unit --------------------------------------------------------

def test_eye_contact_after_three_time_units_gives_attention_then_toys_and_turn() -> None:
    cg = start(focus=C)                 # t=0 on the face: 1
    assert (cg.phase, cg.gaze, cg.toys, cg.opportunity) == (ENGAGE, C, (), 0)
    cg.update(C)                        # 2
    assert not cg.contact and not cg.attention
    cg.update(C)                        # 3: eye contact
    assert cg.contact and cg.attention and cg.phase == ENGAGE and cg.toys == ()
    cg.update(C)                        # toys out, caregiver turns (latency 0)
    assert cg.phase == ATTEND and len(cg.toys) == 2 and cg.trial == 0
    assert cg.gaze == cg.target == place_index(cg.toys[0][0])
    assert not cg.attention
    cg.update(cg.target)                # the robot follows: attention, both on the toy
    assert cg.attention and cg.gaze == cg.target and cg.toys
    cg.update(cg.target)                # toys removed, back to the robot: a new opportunity
    assert (cg.phase, cg.gaze, cg.toys, cg.target, cg.opportunity) == (ENGAGE, C, (), -1, 1)
    assert not cg.attention


def test_attention_during_gaze_attends_the_first_look_at_the_face_once_per_opportunity(
        ) -> None:
    cg = start(CaregiverParams(attention_during_gaze=True), focus=1)
    cg.update(C)                        # first mutual gaze of opportunity 0: attention
    assert cg.attention and not cg.contact
    cg.update(2)
    cg.update(C)                        # back on the face: no second attention
    assert not cg.attention
    cg.update(C)
    cg.update(C)                        # eye contact, already attended in this opportunity
    assert cg.contact and not cg.attention
    cg.update(C)                        # toys out
    cg.update(cg.target)                # gaze following is still rewarded
    assert cg.attention
    cg.update(C)                        # opportunity 1 starts: on the face at once
    assert cg.opportunity == 1 and cg.attention


@pytest.mark.parametrize("during_gaze", [False, True])
def test_looking_away_and_back_cannot_farm_attention(during_gaze: bool) -> None:
    """The loophole an outside tabular agent found: look(centre), look(down) alternately."""
    cg = start(CaregiverParams(attention_during_gaze=during_gaze), focus=1)
    attended = []
    for t in range(200):
        cg.update(C if t % 2 == 0 else 3)
        attended.append((cg.opportunity, cg.attention))
    per_opportunity = Counter(opp for opp, a in attended if a)
    assert not per_opportunity or max(per_opportunity.values()) == 1
    assert sum(per_opportunity.values()) <= 200 // cg.params.contact_timeout + 1
    assert bool(per_opportunity) == during_gaze   # without it, no eye contact: no attention


def test_the_2012_caregiver_attends_every_time_unit_of_mutual_gaze() -> None:
    """``attention_per_unit`` (the ``paper_2012`` model): looking at the face pays at once,
    in every time unit of the wait for eye contact, and looking away and back pays again."""
    cg = ProtocolCaregiver(make_caregiver("paper_2012").params)
    cg.reset(np.random.default_rng(0), 1)
    assert cg.params.attention_per_unit
    attended = []
    for focus in (C, 2, C, C, C):       # on the face, away, back for three units: contact
        cg.update(focus)
        attended.append(cg.attention)
    assert attended == [True, False, True, True, True] and cg.contact
    cg.update(C)                        # toys out, the caregiver turns: nothing for the face
    assert cg.phase == ATTEND and not cg.attention
    cg.update(cg.target)                # gaze following is rewarded as before
    assert cg.attention
    farmed = []
    for t in range(100):                # the loophole is open again: half the time units pay
        cg.update(C if t % 2 == 0 else 3)
        farmed.append(cg.attention)
    assert sum(farmed) == 50 and cg.opportunity > 1


def test_looking_away_breaks_the_streak() -> None:
    cg = start(focus=C)
    cg.update(C)
    cg.update(2)
    cg.update(C)
    cg.update(C)
    assert not cg.contact
    cg.update(C)
    assert cg.contact


def test_no_attention_on_contact_when_disabled() -> None:
    cg = start(CaregiverParams(attention_on_contact=False))
    contact(cg)
    assert not cg.attention


def test_latency_keeps_the_caregiver_on_the_robot_with_toys_out() -> None:
    cg = start(CaregiverParams(latency=2))
    contact(cg)
    for _ in range(2):
        cg.update(C)
        assert cg.phase == PRESENT and cg.gaze == C and len(cg.toys) == 2
    cg.update(C)
    assert cg.phase == ATTEND and cg.gaze == cg.target


def test_timeout_removes_the_toys_without_attention() -> None:
    cg = start(CaregiverParams(timeout=3))
    contact(cg)
    cg.update(C)                                # the turn (age 0)
    wrong = next(i for i in range(1, 6) if i != cg.target)
    for _ in range(3):                          # ages 1..3: the robot looks elsewhere
        assert cg.phase == ATTEND
        cg.update(wrong)
        assert not cg.attention
    cg.update(wrong)
    assert cg.phase == ENGAGE and cg.toys == () and cg.opportunity == 1


def test_single_look_ends_the_trial_at_the_first_wrong_look() -> None:
    cg = start(CaregiverParams(single_look=True))
    contact(cg)
    cg.update(C)
    cg.update(C)                                # staying on the face is not a look
    assert cg.phase == ATTEND
    cg.update(next(i for i in range(1, 6) if i != cg.target))
    cg.update(C)
    assert cg.phase == ENGAGE and cg.opportunity == 1


def test_missed_opportunity_starts_a_new_one_without_toys() -> None:
    cg = start(CaregiverParams(contact_timeout=4), focus=1)   # t=0 is the first time unit
    for _ in range(3):
        cg.update(1)
    assert cg.opportunity == 0
    cg.update(C)
    assert cg.opportunity == 1 and cg.phase == ENGAGE and cg.toys == ()
    cg.update(C)
    cg.update(C)
    assert cg.contact


def test_waits_for_ever_without_contact_timeout() -> None:
    cg = start(CaregiverParams(contact_timeout=None))
    for _ in range(1000):
        cg.update(1)
    assert cg.opportunity == 0


def run_trials(params: CaregiverParams, n: int, seed: int = 0) -> list[tuple]:
    """(target, gaze, toys) of n trials of a robot that follows nothing but makes contact."""
    cg = start(params, seed=seed)
    out = []
    while len(out) < n:
        contact(cg)
        cg.update(C)
        out.append((cg.target, cg.gaze, cg.toys))
        cg.update(cg.target)
        cg.update(1)            # the new opportunity starts with the robot looking away
    return out


def test_reliability_zero_never_looks_at_the_target_and_one_always_does() -> None:
    assert all(g == t for t, g, _ in run_trials(CaregiverParams(reliability=1.0), 200))
    assert all(g != t for t, g, _ in run_trials(CaregiverParams(reliability=0.0), 200))


def test_reliability_one_fifth_makes_the_gaze_uninformative() -> None:
    trials = run_trials(CaregiverParams(reliability=0.2), 2000)
    hits = sum(g == t for t, g, _ in trials) / len(trials)
    assert 0.16 < hits < 0.24
    assert set(Counter(g for _, g, _ in trials)) == {1, 2, 3, 4, 5}


def test_placement_weights_decide_where_toys_go() -> None:
    only = CaregiverParams(placement={"left": 1.0, "right": 3.0})
    trials = run_trials(only, 400)
    assert all({p for p, _ in toys} == {"left", "right"} for _, _, toys in trials)
    targets = Counter(PLACES[t] for t, _, _ in trials)
    assert 0.65 < targets["right"] / 400 < 0.85


def test_evaluation_mode_follows_the_sequence_and_draws_the_distractor() -> None:
    seq = ("down", "left", "right")
    trials = run_trials(CaregiverParams(target_sequence=seq), 9, seed=5)
    assert [PLACES[t] for t, _, _ in trials] == list(seq) * 3
    distractors = {toys[1][0] for _, _, toys in trials}
    assert all(toys[1][0] != toys[0][0] for _, _, toys in trials) and len(distractors) > 1


def test_toys_get_the_colours_in_a_random_order() -> None:
    trials = run_trials(CaregiverParams(), 200)
    assert all(sorted(c for _, c in toys) == ["green", "red"] for _, _, toys in trials)
    first = Counter(toys[0][1] for _, _, toys in trials)
    assert first["red"] > 50 and first["green"] > 50   # colour does not give the target away
    bare = run_trials(CaregiverParams(toy_colours=(), n_toys=1), 5)
    assert all(toys[0][1] == "" for _, _, toys in bare)


def test_same_seed_same_trials() -> None:
    assert run_trials(CaregiverParams(), 50, seed=3) == run_trials(CaregiverParams(), 50, seed=3)
    assert run_trials(CaregiverParams(), 50, seed=3) != run_trials(CaregiverParams(), 50, seed=4)
