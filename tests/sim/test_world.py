"""Worlds that grow: places, toys and colours valid for every size; generated domains that
load, check and agree with the simulator's percepts."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from relrl.cli import main
from relrl.kb import KnowledgeBase
from relrl.sim import SharedAttentionEnv, World, layout, place_names
from relrl.sim.caregiver import evaluation_sequence
from relrl.sim.errors import SimError
from relrl.sim.places import MAX_PLACES, POSITIONS
from relrl.sim.policies import GazeFollower, RandomPolicy, rollout
from relrl.sim.world import colour_names, kind_names

SIS = Path(__file__).resolve().parents[2] / "examples" / "domains" / "sis.pl"
SIZES = [2, 3, 4, 5, 9, 17, 33, MAX_PLACES]


@pytest.mark.parametrize("n", range(2, MAX_PLACES + 1))
def test_place_names_are_distinct_prolog_atoms_for_every_size(n: int) -> None:
    names = place_names(n)
    assert len(names) == len(set(names)) == n and "centre" not in names
    assert all(re.fullmatch(r"[a-z][a-z0-9_]*", p) for p in names)
    assert ("down" in names) == (n % 2 == 1)


def test_the_paper_world_keeps_its_names_and_geometry() -> None:
    lay = layout(5)
    assert lay.toy_places == ("left", "left_down", "down", "right_down", "right")
    assert lay.positions == POSITIONS and lay.positions["left_down"] == (25.0, 20.0, -25.0)


@pytest.mark.parametrize("small,large", [(5, 9), (9, 17), (17, 33)])
def test_a_larger_world_subdivides_the_smaller_one(small: int, large: int) -> None:
    a, b = layout(small), layout(large)
    assert [a.positions[p] for p in a.toy_places] == [b.positions[p] for p in
                                                     b.toy_places[::2]]


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.slow
def test_geometry_is_symmetric_and_spans_the_table(n: int) -> None:
    lay = layout(n)
    ang = np.array(lay.angle_between)
    assert np.allclose(ang, ang.T) and np.all(np.diag(ang) == 0)
    pans = [lay.robot_pan_tilt[p][0] for p in lay.toy_places]
    assert pans == sorted(pans, reverse=True)             # from the robot's left to its right
    assert pans[0] == -pans[-1] == 58.0
    assert all(a > 0 for a in ang[0][1:])                 # no toy place is the caregiver


@pytest.mark.parametrize("n", [1, MAX_PLACES + 1, 0, True, 2.5])
def test_bad_sizes_name_the_value(n) -> None:
    with pytest.raises((SimError, ValueError), match=f"places={n!r}"):
        World(places=n)


@pytest.mark.parametrize(("changes", "message"), [
    ({"toys": 6, "places": 5}, "toys=6"), ({"colours": -1}, "colours=-1"),
    ({"field": 0}, "field=0"), ({"field": float("nan")}, "field=nan"),
    ({"scene": "yes"}, "scene='yes'")])
def test_bad_worlds_name_the_value(changes: dict, message: str) -> None:
    with pytest.raises(SimError, match=re.escape(message)):
        World(**changes)


def test_world_parse_and_its_errors() -> None:
    assert World.parse("places=9, colours=3,scene=true") == World(places=9, colours=3,
                                                                   scene=True)
    for text, message in [("plces=9", "did you mean 'places'"), ("places", "NAME=VALUE"),
                          ("scene=maybe", "scene='maybe'"), ("places=x", "places='x'")]:
        with pytest.raises(SimError, match=re.escape(message)):
            World.parse(text)


@pytest.mark.parametrize("n", [1, 2, 6, 7, 12, 40])
def test_colour_and_kind_names_are_distinct(n: int) -> None:
    for names in (colour_names(n), kind_names(n)):
        assert len(set(names)) == len(names) == n


@pytest.mark.parametrize("n", [2, 5, 9, 17, 33])
def test_evaluation_sequence_is_balanced_and_never_repeats(n: int) -> None:
    places = layout(n).toy_places
    seq = evaluation_sequence(places)
    assert sorted(seq) == sorted(places * 4)
    assert all(seq[k] != seq[k - 1] for k in range(len(seq)))      # cyclically


@pytest.mark.parametrize("world", [
    World(), World(places=2, toys=2), World(places=9, colours=3, kinds=2, toys=3),
    World(places=17, colours=0, scene=True), World(places=33, colours=4, kinds=4, toys=5,
                                                  scene=True, field=30)])
def test_every_world_runs_and_a_gaze_follower_solves_it(world: World) -> None:
    env = SharedAttentionEnv(world=world, max_steps=None)
    trace = rollout(env, GazeFollower(), 1500, seed=world.places)
    summary = env.metrics()
    assert summary["cgi"] == 1.0 and summary["shifts"] > 100
    places = set(env.places)
    toys = [t for rec in trace for t in rec.toys]
    assert {p for p, _ in toys} <= places - {"centre"}
    assert {c for _, c in toys} <= (set(world.colour_names) or {""})
    assert {k for rec in trace for k in rec.kinds} <= set(world.kind_names)
    assert all(len(rec.toys) == world.toys for rec in trace if rec.toys)
    random_env = SharedAttentionEnv(world=world, max_steps=None)
    random = rollout(random_env, RandomPolicy(1, env.places), 1500, seed=1)
    assert {rec.focus for rec in random} == places           # every response is a place
    vocabulary = world.vocabulary()                           # the shared vocabulary's form
    _, info = random_env.reset(seed=2)
    for _ in range(500):
        assert all(vocabulary.allows(p) for p in info["percepts"]), info["percepts"]
        _, _, _, _, info = random_env.step(random_env.action_space.sample())


def test_whole_scene_perception_sees_the_toys_in_the_field_only() -> None:
    world = World(places=9, kinds=2, scene=True, field=40)
    env = SharedAttentionEnv(world=world, max_steps=None)
    env.reset(seed=3, options={"focus": "centre"})
    for _ in range(3):
        _, _, _, _, info = env.step(0)                 # eye contact, then toys out
    cg, lay = env.caregiver, world.layout
    seen = {p[1]: p[2:] for p in info["percepts"] if p[0] == "in_view"}
    for place, colour in cg.toys:
        near = lay.angle_between[0][lay.index(place)] <= 40
        assert (place in seen) == near
        if near:
            assert seen[place] == (colour, cg.kind_at[lay.index(place)])
    focus_only = SharedAttentionEnv(world=World(places=9, kinds=2), max_steps=None)
    focus_only.reset(seed=3, options={"focus": "centre"})
    percepts = [focus_only.step(0)[4]["percepts"] for _ in range(3)][-1]
    assert not any(p[0] == "in_view" for p in percepts)


@pytest.mark.parametrize("world", [World(), World(places=9, colours=3),
                                   World(places=17, kinds=3, scene=True),
                                   World(places=33, colours=4, kinds=2, scene=True)])
def test_relrl_check_accepts_every_generated_domain(world: World, tmp_path: Path,
                                                    capsys) -> None:
    path = world.write_domain(tmp_path)
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert f"look({world.layout.toy_places[-1]})" in out and "is valid" in out
    n_facts = 1 + world.places + (world.places + 1) + world.places + world.colours + world.kinds
    assert len(re.findall(r"fact\(", out)) == n_facts


def test_examples_sis_pl_is_the_paper_worlds_generated_domain() -> None:
    """One template: the shipped domain is the paper's world's, as relrl.sim.domain writes it
    (regenerate it with World().write_domain("examples/domains", "sis"))."""
    assert SIS.read_text() == World().domain_text()


@pytest.mark.parametrize("world", [World(places=9, colours=3, kinds=2),
                                   World(places=9, colours=2, kinds=2, scene=True)])
@pytest.mark.slow
def test_the_domain_reads_the_simulators_percepts(world: World, tmp_path: Path) -> None:
    """Facts of the generated domain hold exactly when the percepts of this time unit or
    the one before (the domain's memory span) say so."""
    kb = KnowledgeBase(world.write_domain(tmp_path))
    try:
        env = SharedAttentionEnv(world=world, max_steps=None)
        follower = GazeFollower()
        _, info = env.reset(seed=5)
        before: list = []
        for _ in range(300):
            now = info["percepts"]
            kb.insert(now)
            recent = now + before
            gazes = {p[2] for p in recent if p[0] == "pose"}
            for place in env.places[1:]:
                assert kb.holds((f"gaze_{place}", "face")) == (place in gazes)
            assert kb.holds(("head_at", info["record"].focus))
            toys = {p[2] for p in recent if p[:2] == ("at", "toy")}
            toys |= {p[1] for p in recent if p[0] == "in_view"}
            for place in env.places[1:]:
                assert kb.holds(("toy_at", place)) == (place in toys)
            colours = {p[2] for p in recent if p[:2] == ("colour", "toy")}
            if any(p == ("see", "toy") for p in recent):
                for colour in world.colour_names:
                    assert kb.holds((f"{colour}_toy", "toy")) == (colour in colours)
            before = now
            _, _, _, _, info = env.step(follower(now))
    finally:
        kb.close()


def test_write_domain_leaves_an_unchanged_file_alone(tmp_path: Path) -> None:
    w = World(places=9)
    path = w.write_domain(tmp_path)
    stamp = path.stat().st_mtime_ns
    assert w.write_domain(tmp_path) == path and path.stat().st_mtime_ns == stamp
    assert path.stat().st_mode & 0o777 == 0o644


def test_env_rejects_a_caregiver_of_another_world() -> None:
    from relrl.sim.caregiver import make_caregiver

    with pytest.raises(SimError, match="not the world's"):
        SharedAttentionEnv(make_caregiver("paper"), world=World(places=9))
