"""Invariants of the simulator for any caregiver parameters and any responses (hypothesis)."""

from __future__ import annotations

import itertools
from collections import Counter

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from relrl.sim import CaregiverParams, GazeMetrics, SharedAttentionEnv
from relrl.sim.places import TOY_PLACES

pytestmark = pytest.mark.slow  # every test here takes a second or more

params = st.builds(
    CaregiverParams,
    n_toys=st.integers(1, 5),
    reliability=st.floats(0.0, 1.0),
    latency=st.integers(0, 3),
    timeout=st.integers(1, 6),
    contact_hold=st.integers(1, 4),
    contact_timeout=st.one_of(st.none(), st.integers(4, 12)),
    attention_on_contact=st.booleans(),
    attention_during_gaze=st.booleans(),
    attention_per_unit=st.booleans(),
    single_look=st.booleans(),
    target_sequence=st.one_of(st.none(), st.lists(st.sampled_from(TOY_PLACES), min_size=1,
                                                  max_size=5).map(tuple)),
)


@settings(max_examples=60, deadline=None)
@given(p=params, actions=st.lists(st.integers(0, 5), min_size=1, max_size=300),
       seed=st.integers(0, 2**32 - 1))
def test_invariants(p: CaregiverParams, actions: list[int], seed: int) -> None:
    env = SharedAttentionEnv(caregiver_params=p, max_steps=None)
    env.reset(seed=seed)
    for a in actions:
        env.step(a)
    trace = env.trace
    for prev, rec in itertools.pairwise(trace):
        places = [pl for pl, _ in rec.toys]
        assert len(set(places)) == len(places) and "centre" not in places
        assert rec.toys == () or len(rec.toys) == p.n_toys
        assert (rec.target is None) == (rec.toys == ()) and (
            rec.target is None or rec.target == rec.toys[0][0])
        if rec.phase == "engage":
            assert rec.gaze == "frontal" and rec.toys == ()
        if rec.attention:   # attention only for the face (once) or for looking at the target
            assert ((rec.contact and p.attention_on_contact)
                    or ((p.attention_during_gaze or p.attention_per_unit)
                        and rec.focus == "centre")
                    or rec.focus == rec.target)
        if rec.contact:
            assert rec.phase == "engage" and rec.focus == "centre"
        assert rec.opportunity in (prev.opportunity, prev.opportunity + 1)
        assert rec.trial in (prev.trial, prev.trial + 1)
        if p.reliability == 1.0 and rec.phase == "attend":
            assert rec.gaze == rec.target
    face_attention = Counter(r.opportunity for r in trace if r.attention and r.phase == "engage")
    if not p.attention_per_unit:   # at most once per opportunity (the 2012 caregiver: each unit)
        assert all(n == 1 for n in face_attention.values())
    else:
        assert all(r.attention for r in trace[1:] if r.phase == "engage" and r.focus == "centre")
    m = GazeMetrics(hold=p.contact_hold).extend(trace)
    contacts = sum(r.contact for r in trace)
    assert m.eye_contacts().established == contacts   # the metric agrees with the caregiver
    if p.target_sequence is not None:
        targets = [r.target for r in trace if r.target is not None]
        trials = sorted({(r.trial, r.target) for r in trace if r.target is not None})
        assert all(t == p.target_sequence[k % len(p.target_sequence)] for k, t in trials)
        assert set(targets) <= set(p.target_sequence)
