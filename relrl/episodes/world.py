"""The world of an episode: a caregiver that follows a script, objects, and the robot's view.

:class:`EpisodeWorld` is an :class:`~relrl.interfaces.Environment`. Each time unit the robot's
response turns its head (``look(P)``) or names what it sees (``name_object``); the caregiver
advances one time unit (:class:`ProtocolCaregiver` for experiment 2, plus the script's
events); then the robot perceives its focus. In ``render`` mode the view is drawn by
:func:`perception.render.render` and read back by the real perception pipeline
(:class:`perception.Perceiver`), so the facts come from pixels; ``symbolic`` mode writes the
same facts directly (fast, for tests and quick scripts).

``info`` carries ``percepts``, ``record`` (a :class:`relrl.sim.metrics.StepRecord`, so the
simulator's metrics -- CGI, eye contacts -- apply), ``features`` (the ART2 colour features of
the object in view, render mode only) and ``scene`` (what the caregiver does).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from perception.vocabulary import FRUIT_COLOURS, GAZE_POSE
from relrl.episodes.script import PLACES, Episode, Event
from relrl.interfaces import Environment
from relrl.sim.metrics import StepRecord
from relrl.terms import Term, format_term

__all__ = ["GAZE_POSE", "KIND_COLOUR", "EpisodeWorld", "ProtocolCaregiver", "Scene"]

# GAZE_POSE: the head pose a caregiver shows while looking at each place (the episode world's
# vocabulary, from percepts).
#: the colour perception reports for each object kind (symbolic mode).
KIND_COLOUR: dict[str, str] = FRUIT_COLOURS


@dataclass
class Scene:
    """What the caregiver does in one time unit.

    Attributes:
        look: where the caregiver looks (``centre`` = at the robot).
        objects: place -> object kind.
        attention: the caregiver gives attention (reinforcer) in this time unit.
        words: what the caregiver says in this time unit.
        mode: the caregiver's phase (``engage``, ``present``, ``attend``, ``joint``, ``script``).
        opportunity: eye-contact opportunity number.
        trial: presentation number (-1 before the first).
        target: place of the presented object, or ``None``.
        contact: eye contact was established in this time unit.
    """

    look: str = "centre"
    objects: dict[str, str] = field(default_factory=dict)
    attention: bool = False
    words: list[str] = field(default_factory=list)
    mode: str = "engage"
    opportunity: int = 0
    trial: int = -1
    target: str | None = None
    contact: bool = False


class ProtocolCaregiver:
    """The caregiver of experiment 2 (section 5.2), one decision per time unit.

    * ``engage``: looks at the robot until eye contact (the robot on its face for
      ``contact_hold`` time units); gives attention in the time unit of eye contact and after
      it, and, with ``gaze_attention`` (default), in every time unit the robot looks at its
      face (Triesch et al.'s reward for looking at the caregiver, as in Experiment 1); a new
      opportunity starts after ``contact_timeout`` units without contact. Without objects
      the eye contact is held ``joint`` more units (or until the robot looks away) and then a
      new opportunity starts, so that every interaction cycle ends.
    * ``present`` (only when the phase has objects): with ``latency`` 0 (default), in the time
      unit of eye contact a fruit appears at a place and the caregiver turns to it (random in
      learning, a fixed cycle in evaluation); otherwise ``latency`` units later.
    * ``attend``: when the robot looks at the fruit the caregiver looks at, the caregiver gives
      attention and says the fruit's name (``hear(Word)``); after ``timeout`` units without it
      the fruit is removed. With ``first_shift`` (the paper's evaluation) only the robot's
      first turn away from the face is checked: a turn elsewhere ends the presentation.
    * ``joint``: both look at the fruit for up to ``joint`` units; naming it (``name_object``)
      earns attention; then the fruit is removed and the caregiver looks at the robot again.

    An interaction cycle (one ``opportunity``) runs from the caregiver turning to the robot to
    the next time she does: eye contact, then (with objects) the presentation.

    Args:
        episode: the script (caregiver parameters, fruits, places, names).
        sequence: place the fruits in a pre-established cycle (evaluation) instead of at random.
        first_shift: check only the robot's first turn of each presentation (evaluation).
    """

    def __init__(self, episode: Episode, *, sequence: bool = False,
                 first_shift: bool = False) -> None:
        self.p = dict(episode.caregiver)
        self.fruits = episode.fruits
        self.places = episode.places
        self.word_for = episode.word_for
        self.sequence = sequence
        self.first_shift = first_shift
        self.rng = np.random.default_rng(0)
        self.scene = Scene()
        self._streak = 0
        self._timer = 0
        self._kind: str | None = None
        self._held = False
        self._missed = False

    def reset(self, rng: np.random.Generator) -> Scene:
        """Start over: looking at the robot, nothing on the table."""
        self.rng = rng
        self.scene = Scene()
        self._streak = self._timer = 0
        self._kind = None
        self._held = self._missed = False
        return self.scene

    def _next_fruit(self) -> tuple[str, str]:
        n = self.scene.trial
        if self.sequence:
            # a pre-established sequence: every place in turn, fruits in turn
            return self.places[n % len(self.places)], self.fruits[n % len(self.fruits)]
        return (self.places[int(self.rng.integers(len(self.places)))],
                self.fruits[int(self.rng.integers(len(self.fruits)))])

    def _present(self) -> None:
        s = self.scene
        s.trial += 1
        place, self._kind = self._next_fruit()
        s.objects, s.look, s.target = {place: self._kind}, place, place
        s.mode, self._timer = "attend", 0

    def _end_trial(self) -> None:
        s = self.scene
        s.objects, s.look, s.mode, s.target = {}, "centre", "engage", None
        self._next_cycle()

    def _next_cycle(self) -> None:
        self.scene.opportunity += 1
        self._streak = self._timer = 0
        self._held = self._missed = False

    def advance(self, focus: str, named: bool, objects: bool) -> Scene:
        """One time unit, seeing where the robot now looks and whether it named the object."""
        s = self.scene
        s.attention, s.words, s.contact = False, [], False
        p = self.p
        if s.mode == "engage":
            self._streak = self._streak + 1 if focus == "centre" else 0
            self._timer += 1
            s.attention = focus == "centre" and p["gaze_attention"]
            if self._held and focus != "centre":
                self._next_cycle()          # no objects: the robot looked away after contact
            elif self._streak >= p["contact_hold"]:
                s.attention = True
                s.contact = self._streak == p["contact_hold"]
                if objects and p["latency"] == 0:
                    self._present()
                elif objects:
                    s.mode, self._timer = "present", 0
                else:
                    self._held = True
                    if self._streak >= p["contact_hold"] + p["joint"]:
                        self._next_cycle()  # eye contact held: the cycle is over
            elif self._timer >= p["contact_timeout"]:
                s.opportunity += 1
                self._timer = 0
        elif s.mode == "present":
            self._timer += 1
            if self._timer >= p["latency"]:
                self._present()
        elif s.mode == "attend":
            self._timer += 1
            if focus == s.target:
                s.attention = True
                s.words = [self.word_for(self._kind or "")]
                s.mode, self._timer = "joint", 0
            elif self.first_shift and focus != "centre":
                s.mode, self._timer, self._missed = "joint", 0, True
            elif self._timer >= p["timeout"]:
                self._end_trial()
        elif s.mode == "joint":
            self._timer += 1
            if named and focus == s.target and not self._missed:
                s.attention = True
            if self._missed or named or focus != s.target or self._timer >= p["joint"]:
                self._end_trial()
        return s

    def apply(self, event: Event) -> None:
        """Add a scripted event to this time unit."""
        s = self.scene
        if event.look is not None:
            s.look = event.look
            s.target = event.look if event.look != "centre" else None
        if "all" in event.remove:
            s.objects = {}
        for place in event.remove:
            s.objects.pop(place, None)
        s.objects.update(event.show)
        s.words = s.words + list(event.say)
        s.attention = s.attention or event.attention


class EpisodeWorld(Environment):
    """An episode's world as an :class:`~relrl.interfaces.Environment`.

    Time is counted in the script's time unit (:attr:`units_done`): control steps
    (``time_unit = "step"``) or interaction cycles of the protocol caregiver
    (``"interaction"``: one eye-contact opportunity and, with objects, its presentation).

    With ``variation = "camera"`` in render mode every frame is drawn as a webcam in a lit room
    would see it (:mod:`perception.appearance`): the room's light is the same for every world
    of the run (drawn from the episode's seed: the paper did not change the light), white
    balance and the fruit (shade, shape, size, place in view, the caregiver's hand) change
    with each presentation, exposure, blur and noise with each frame.

    Args:
        episode: the script.
        protocol_only: the protocol caregiver with objects all the time and no script events
            (evaluation runs and naming executions), whatever the phases say.
        sequence: place fruits in a pre-established cycle (evaluation) instead of at random.
        first_shift: check only the robot's first turn of each presentation (evaluation).
        perceiver: a :class:`perception.Perceiver` to share (render mode).
        max_units: truncate after this many time units (``None``: never).
    """

    def __init__(self, episode: Episode, *, protocol_only: bool = False, sequence: bool = False,
                 first_shift: bool = False, perceiver: Any = None,
                 max_units: int | None = None) -> None:
        self.episode = episode
        self.protocol_only = protocol_only
        self.caregiver = ProtocolCaregiver(episode, sequence=sequence, first_shift=first_shift)
        self.max_units = max_units
        self.render_mode = episode.perception == "render"
        self.cycles = episode.time_unit == "interaction"
        self._perceiver = perceiver
        self._events: dict[int, list[Event]] = {}
        if not protocol_only:
            for ev in episode.events:
                self._events.setdefault(ev.t, []).append(ev)
        self.rng = np.random.default_rng(episode.seed)
        self.t = 0
        self.focus = "centre"
        self.heard: list[str] = []
        self.last_frame: np.ndarray | None = None
        self.last_percept: Any = None  # what perception found in last_frame (the monitor)
        self.variation = None
        if self.render_mode and episode.variation == "camera":
            from perception.appearance import Variation

            self.variation = Variation(exposure=episode.lighting)
            # the room: one light for every world of this run
            self.room = self.variation.session_light(np.random.default_rng([episode.seed, 7]))
        self._look_rng = np.random.default_rng(0)
        self._looks: dict[str, tuple[int, str, Any]] = {}
        self._light: Any = None
        self._moved = False
        self._unit = 1

    @property
    def units_done(self) -> int:
        """Time units completed: control steps, or interaction cycles."""
        return self.caregiver.scene.opportunity if self.cycles else self.t

    @property
    def perceiver(self) -> Any:
        """The perception pipeline (created on first use)."""
        if self._perceiver is None:
            from perception import Perceiver

            self._perceiver = Perceiver()
        return self._perceiver

    def hear(self, word: str) -> None:
        """A word typed or recognised: perceived as ``hear(Word)`` in the next time unit."""
        self.heard.append(word)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[Any, dict[str, Any]]:
        """Start the episode: the caregiver looks at the robot, the robot at ``options['focus']``
        (default: a place drawn from the seeded generator)."""
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.t = 0
        self.caregiver.reset(self.rng)
        focus = (options or {}).get("focus")
        self.focus = focus if focus in PLACES else PLACES[int(self.rng.integers(len(PLACES)))]
        # appearance draws from a stream of its own: the same caregiver with or without it
        self._look_rng = np.random.default_rng([int(self.rng.integers(2**31)), 11])
        self._looks, self._light, self._moved, self._unit = {}, None, False, 1
        if self.render_mode:
            self.perceiver.reset()
        return None, self._observe(named=False)

    def step(self, action: Term) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """Apply the response, advance the caregiver and the script one time unit, perceive."""
        named = action == "name_object"
        before = self.focus
        if isinstance(action, tuple) and action[0] == "look" and action[1] in PLACES:
            self.focus = action[1]
        self._moved = self.focus != before
        self.t += 1
        self._unit = self.units_done + 1 if self.cycles else self.t
        phase = self.episode.phase_at(self._unit)
        objects = True if self.protocol_only else phase.objects
        if self.protocol_only or phase.caregiver == "protocol":
            self.caregiver.advance(self.focus, named, objects)
        else:
            s = self.caregiver.scene
            s.attention, s.words, s.contact, s.mode = False, [], False, "script"
        for ev in self._events.get(self.t, ()):
            self.caregiver.apply(ev)
        info = self._observe(named)
        truncated = self.max_units is not None and self.units_done >= self.max_units
        reward = 1.0 if self.caregiver.scene.attention else 0.0
        return None, reward, False, truncated, info

    def _appearance(self, scene: Scene) -> Any:
        """This frame's appearance: a new light and new fruit looks with each presentation."""
        from perception.appearance import Appearance

        var, rng = self.variation, self._look_rng
        if self._light is None or self._light[0] != scene.opportunity:
            self._light = (scene.opportunity, var.light(rng, self.room))
        for place, kind in scene.objects.items():
            held = self._looks.get(place)
            if held is None or held[:2] != (scene.trial, kind):
                self._looks[place] = (scene.trial, kind, var.fruit(rng, kind)
                                      if kind in var.shades else None)
        looks = {p: look for p, (_, _, look) in self._looks.items()
                 if p in scene.objects and look is not None}
        return Appearance(var.exposed(rng, self._light[1]), var.optics(rng, self._moved), looks)

    def _view_facts(self, scene: Scene) -> tuple[list[Term], np.ndarray | None]:
        focus = self.focus
        kind = scene.objects.get(focus)
        if not self.render_mode:
            if focus == "centre":
                return [("see", "face"), ("pose", "face", GAZE_POSE[scene.look])], None
            if kind is None:
                return [("see", "environment")], None
            colour = KIND_COLOUR.get(kind, kind)
            return [("see", "object"), ("colour", "object", colour),
                    ("at", "object", focus)], None
        from perception.art2 import colour_features
        from perception.render import SceneView, render

        low, high = self.episode.lighting
        if self.variation is not None:
            app, gain = self._appearance(scene), 1.0
        else:
            app, gain = None, float(self.rng.uniform(low, high))
        view = SceneView(focus, GAZE_POSE[scene.look], dict(scene.objects), gain,
                         int(self.rng.integers(2**31)), app)
        frame = render(view)
        self.last_frame = frame
        percept = self.perceiver.analyse(frame, looking_at=focus)
        self.last_percept = percept
        facts = [f for f in percept.facts if not (isinstance(f, tuple) and f[0] in
                                                  ("pan", "tilt"))]
        if not facts:
            facts = [("see", "environment")]
        features = colour_features(percept.colour) if percept.colour is not None else None
        return facts, features

    def _observe(self, named: bool) -> dict[str, Any]:
        scene = self.caregiver.scene
        facts, features = self._view_facts(scene)
        percepts: list[Term] = facts + [("at", self.focus)]
        if scene.attention:
            percepts.append(("hear", "attention"))
        words = list(scene.words) + self.heard
        self.heard = []
        percepts += [("hear", w) for w in words]
        record = StepRecord(self.t, self.focus, "frontal" if scene.look == "centre"
                            else scene.look, scene.mode, scene.opportunity, scene.trial,
                            tuple(scene.objects.items()), scene.target, scene.attention,
                            scene.contact)
        return {"percepts": percepts, "record": record, "features": features,
                "words": words, "named": named,
                "scene": {"look": scene.look, "objects": dict(scene.objects),
                          "mode": scene.mode, "target": scene.target,
                          "kind": scene.objects.get(scene.target or "", None)},
                "unit": self._unit, "phase": self.episode.phase_at(self._unit).name}

    def close(self) -> None:
        """Nothing to release."""


def describe(percepts: Sequence[Term]) -> str:
    """Percepts as ``see(face), pose(face,frontal), ...`` for the live view."""
    return ", ".join(format_term(p) for p in percepts)
