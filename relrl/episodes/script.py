"""Episode scripts: TOML files that script a caregiver, a world and a learner over time.

:func:`load_episode` reads and checks a script and returns an :class:`Episode`. Every problem
is an :class:`EpisodeError` naming ``file:line`` and the problem; syntax errors come from
``tomllib`` (which gives the line), problems of meaning (an unknown key, a place that does not
exist, a negative number of steps) are located by finding the key's line in the text.

See ``docs/episodes.md`` for the format, with examples.
"""

from __future__ import annotations

import difflib
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from relrl.errors import UserError

__all__ = [
    "OBJECT_PLACES",
    "PLACES",
    "TIME_UNITS",
    "Episode",
    "EpisodeError",
    "Event",
    "Phase",
    "load_episode",
    "parse_episode",
]

#: where the head (and the caregiver) can look; ``centre`` is the other's face.
PLACES: tuple[str, ...] = ("centre", "left", "left_down", "down", "right_down", "right")
#: where objects can appear.
OBJECT_PLACES: tuple[str, ...] = PLACES[1:]
_KINDS = ("apple", "lemon", "orange", "lime", "red", "orange", "yellow", "green", "blue",
          "purple")
_CAREGIVERS = ("protocol", "script")
_PERCEPTION = ("render", "symbolic")
#: what a time unit is: a control step, or an interaction cycle of the protocol caregiver
#: (eye contact and, with objects, one presentation; docs/episodes.md).
TIME_UNITS = ("step", "interaction")
_VARIATION = ("none", "camera")
_EVAL_POLICIES = ("behaviour", "greedy")


class EpisodeError(UserError):
    """A problem in an episode script: ``file:line: problem``."""


@dataclass
class Phase:
    """A stretch of the episode's time line.

    Attributes:
        name: shown in the trace and the live view.
        steps: time units.
        caregiver: ``protocol`` (the caregiver of experiment 2 drives the scene; events add to
            it) or ``script`` (only the events change the scene).
        objects: the protocol caregiver presents fruits in this phase.
        learning: the learner learns in this phase.
    """

    name: str
    steps: int
    caregiver: str = "protocol"
    objects: bool = True
    learning: bool = True


@dataclass
class Event:
    """What the caregiver does at time unit ``t`` (counted from 1 over the whole episode).

    Attributes:
        t: the time unit.
        look: where the caregiver looks from now on (``centre`` = at the robot).
        show: objects that appear, place -> kind.
        remove: places whose object is taken away (``"all"`` clears the table).
        say: words the robot hears in this time unit (``hear(Word)``).
        attention: the caregiver gives attention (the reinforcer) in this time unit.
        line: the script line of the event.
    """

    t: int
    look: str | None = None
    show: dict[str, str] = field(default_factory=dict)
    remove: list[str] = field(default_factory=list)
    say: list[str] = field(default_factory=list)
    attention: bool = False
    line: int = 0


@dataclass
class Episode:
    """A checked episode script (all paths resolved against the script's folder)."""

    path: Path
    name: str = "episode"
    domain: Path = Path("examples/domains/fruits.pl")
    seed: int = 0
    learner: str = "etg"
    learner_params: dict[str, float] = field(default_factory=dict)
    policy_load: Path | None = None
    policy_save: str | None = "policy.pl"
    time_unit: str = "step"
    perception: str = "render"
    variation: str = "none"
    lighting: tuple[float, float] = (0.9, 1.1)
    fruits: tuple[str, ...] = ("apple", "lime", "orange")
    names: dict[str, str] = field(default_factory=dict)
    places: tuple[str, ...] = OBJECT_PLACES
    caregiver: dict[str, Any] = field(default_factory=dict)
    phases: list[Phase] = field(default_factory=list)
    events: list[Event] = field(default_factory=list)
    evaluation: dict[str, Any] | None = None
    naming: dict[str, int] | None = None
    speech: dict[str, Any] = field(default_factory=dict)

    @property
    def steps(self) -> int:
        """Time units of all phases."""
        return sum(p.steps for p in self.phases)

    def phase_at(self, t: int) -> Phase:
        """The phase of time unit ``t`` (1-based); the last phase after the end."""
        end = 0
        for phase in self.phases:
            end += phase.steps
            if t <= end:
                return phase
        return self.phases[-1]

    def word_for(self, kind: str) -> str:
        """The caregiver's word for an object kind."""
        return self.names.get(kind, kind)


# ---- locating keys in the text -----------------------------------------------------------------

_HEADER = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\-]+)\s*\]\]?")


def _locate(text: str, path: tuple[str | int, ...]) -> int:
    """The 1-based line of the key at ``path`` (table, [array index], key...); best effort."""
    lines = text.splitlines()
    table = path[0]
    index = path[1] if len(path) > 1 and isinstance(path[1], int) else None
    rest = [p for p in path[1:] if not isinstance(p, int)]
    seen = -1
    start = None
    for i, line in enumerate(lines):
        m = _HEADER.match(line)
        if m and m.group(2) == table:
            seen += 1
            if index is None or seen == index:
                start = i
                break
    if start is None:
        return 1
    key = rest[0] if rest else None
    if key is None:
        return start + 1
    for j in range(start + 1, len(lines)):
        if _HEADER.match(lines[j]):
            break
        if re.match(rf"^\s*{re.escape(str(key))}\s*=", lines[j]):
            return j + 1
    return start + 1


class _Checker:
    """Reads values out of the parsed TOML, raising located errors."""

    def __init__(self, path: Path, text: str) -> None:
        self.path = path
        self.text = text

    def fail(self, where: tuple[str | int, ...], problem: str) -> EpisodeError:
        return EpisodeError(f"{self.path}:{_locate(self.text, where)}: {problem}")

    def keys(self, table: dict[str, Any], allowed: tuple[str, ...], where: tuple) -> None:
        for key in table:
            if key not in allowed:
                close = difflib.get_close_matches(key, allowed, n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else \
                    f" (known: {', '.join(allowed)})"
                raise self.fail(where + (key,), f"unknown key {key!r} in [{where[0]}]{hint}")

    def get(self, table: dict[str, Any], key: str, kind: type | tuple, default: Any,
            where: tuple) -> Any:
        if key not in table:
            return default
        value = table[key]
        ok = isinstance(value, kind) and not (isinstance(value, bool) and kind in (int, float))
        if kind is float and isinstance(value, int) and not isinstance(value, bool):
            ok, value = True, float(value)
        if not ok:
            name = kind.__name__ if isinstance(kind, type) else "/".join(k.__name__ for k in kind)
            raise self.fail(where + (key,), f"{key} must be a {name}, not {value!r}")
        return value

    def positive(self, table: dict[str, Any], key: str, default: int, where: tuple,
                 minimum: int = 1) -> int:
        value = self.get(table, key, int, default, where)
        if value < minimum:
            raise self.fail(where + (key,), f"{key} must be at least {minimum}, not {value}")
        return value

    def choice(self, value: str, choices: tuple[str, ...], what: str, where: tuple) -> str:
        if value not in choices:
            close = difflib.get_close_matches(str(value), choices, n=1)
            hint = f"did you mean {close[0]!r}?" if close else f"use one of {', '.join(choices)}"
            raise self.fail(where, f"unknown {what} {value!r}; {hint}")
        return value


_TOP = ("episode", "learner", "world", "caregiver", "phase", "event", "evaluation", "naming",
        "speech")


def parse_episode(text: str, path: str | Path = "<episode>") -> Episode:
    """Parse and check an episode script given as text (``path`` names it in errors)."""
    path = Path(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"at line (\d+)", str(exc))
        line = m.group(1) if m else "1"
        problem = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(exc))
        raise EpisodeError(f"{path}:{line}: {problem}") from None
    c = _Checker(path, text)
    for key in data:
        if key not in _TOP:
            close = difflib.get_close_matches(key, _TOP, n=1)
            hint = f" (did you mean [{close[0]}]?)" if close else ""
            raise c.fail((key,), f"unknown table [{key}]{hint}")
    base = path.parent
    ep = Episode(path=path)

    head = data.get("episode", {})
    w = ("episode",)
    c.keys(head, ("name", "domain", "seed", "learner", "policy_load", "policy_save",
                  "time_unit"), w)
    ep.name = c.get(head, "name", str, path.stem, w)
    domain = c.get(head, "domain", str, None, w)
    if domain is None:
        raise c.fail(w, "[episode] needs domain = \"path/to/domain.pl\"")
    ep.domain = (base / domain).resolve()
    if not ep.domain.exists():
        raise c.fail(w + ("domain",), f"domain file {domain!r} not found (looked for "
                     f"{ep.domain})")
    ep.seed = c.get(head, "seed", int, 0, w)
    ep.learner = c.get(head, "learner", str, "etg", w)
    from relrl.learners import LEARNERS

    c.choice(ep.learner, tuple(sorted(LEARNERS)), "learner", w + ("learner",))
    load = c.get(head, "policy_load", str, "", w)
    if load:
        ep.policy_load = (base / load).resolve()
        if not ep.policy_load.exists():
            raise c.fail(w + ("policy_load",), f"policy file {load!r} not found")
    ep.policy_save = c.get(head, "policy_save", str, "policy.pl", w) or None
    ep.time_unit = c.choice(c.get(head, "time_unit", str, "step", w), TIME_UNITS, "time unit",
                            w + ("time_unit",))

    params = data.get("learner", {})
    for key, value in params.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise c.fail(("learner", key), f"learner parameter {key} must be a number, "
                         f"not {value!r}")
        ep.learner_params[key] = float(value)
    from relrl.errors import ConfigError
    from relrl.learners import make_learner

    try:
        make_learner(ep.learner, **ep.learner_params)
    except ConfigError as exc:
        bad = [k for k in params if re.search(rf"\b{re.escape(k)}\b", str(exc))]
        where = ("learner", bad[0]) if bad else ("learner",)
        raise c.fail(where, str(exc)) from None

    world = data.get("world", {})
    w = ("world",)
    c.keys(world, ("perception", "variation", "lighting", "fruits", "names", "places"), w)
    ep.perception = c.choice(c.get(world, "perception", str, "render", w), _PERCEPTION,
                             "perception mode", w + ("perception",))
    ep.variation = c.choice(c.get(world, "variation", str, "none", w), _VARIATION,
                            "appearance variation", w + ("variation",))
    light = c.get(world, "lighting", (float, int, list), [0.9, 1.1], w)
    light = [light, light] if not isinstance(light, list) else light
    if len(light) != 2 or not all(isinstance(x, (int, float)) and 0.05 <= x <= 3.0
                                  for x in light) or light[0] > light[1]:
        raise c.fail(w + ("lighting",), f"lighting must be a number or [low, high] within "
                     f"0.05..3.0, not {world.get('lighting')!r}")
    ep.lighting = (float(light[0]), float(light[1]))
    fruits = c.get(world, "fruits", list, list(ep.fruits), w)
    for kind in fruits:
        c.choice(kind, _KINDS, "object", w + ("fruits",))
    ep.fruits = tuple(fruits)
    names = c.get(world, "names", dict, {}, w)
    for kind, word in names.items():
        if not isinstance(word, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", word):
            raise c.fail(w + ("names",), f"the name of {kind} must be a lower-case word, "
                         f"not {word!r}")
    ep.names = dict(names)
    places = c.get(world, "places", list, list(OBJECT_PLACES), w)
    for place in places:
        c.choice(place, OBJECT_PLACES, "object place", w + ("places",))
    ep.places = tuple(places)

    care = data.get("caregiver", {})
    w = ("caregiver",)
    c.keys(care, ("contact_hold", "contact_timeout", "timeout", "joint", "latency",
                  "gaze_attention"), w)
    ep.caregiver = {
        "contact_hold": c.positive(care, "contact_hold", 3, w),
        "contact_timeout": c.positive(care, "contact_timeout", 12, w),
        "timeout": c.positive(care, "timeout", 6, w),
        "joint": c.positive(care, "joint", 2, w),
        "latency": c.positive(care, "latency", 0, w, minimum=0),
        "gaze_attention": c.get(care, "gaze_attention", bool, True, w),
    }

    phases = data.get("phase", [])
    if not isinstance(phases, list) or not phases:
        raise c.fail(("phase",), "the script needs at least one [[phase]] with steps = N")
    for i, ph in enumerate(phases):
        w = ("phase", i)
        c.keys(ph, ("name", "steps", "caregiver", "objects", "learning"), w)
        if "steps" not in ph:
            raise c.fail(w, f"[[phase]] number {i + 1} needs steps = N")
        ep.phases.append(Phase(
            name=c.get(ph, "name", str, f"phase {i + 1}", w),
            steps=c.positive(ph, "steps", 1, w),
            caregiver=c.choice(c.get(ph, "caregiver", str, "protocol", w), _CAREGIVERS,
                               "caregiver", w + ("caregiver",)),
            objects=c.get(ph, "objects", bool, True, w),
            learning=c.get(ph, "learning", bool, True, w)))

    for i, ev in enumerate(data.get("event", [])):
        w = ("event", i)
        c.keys(ev, ("t", "look", "show", "remove", "say", "attention"), w)
        if "t" not in ev:
            raise c.fail(w, "[[event]] needs t = TIME_UNIT")
        t = c.positive(ev, "t", 1, w)
        if t > ep.steps:
            raise c.fail(w + ("t",), f"t = {t} is after the last time unit ({ep.steps})")
        look = c.get(ev, "look", str, None, w)
        if look is not None:
            c.choice(look, PLACES, "place", w + ("look",))
        show = c.get(ev, "show", dict, {}, w)
        for place, kind in show.items():
            c.choice(place, OBJECT_PLACES, "object place", w + ("show",))
            c.choice(kind, _KINDS, "object", w + ("show",))
        remove = c.get(ev, "remove", (list, str), [], w)
        remove = [remove] if isinstance(remove, str) else remove
        for place in remove:
            c.choice(place, OBJECT_PLACES + ("all",), "place", w + ("remove",))
        say = c.get(ev, "say", (list, str), [], w)
        say = say.split() if isinstance(say, str) else say
        for word in say:
            if not isinstance(word, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", word):
                raise c.fail(w + ("say",), f"say: {word!r} is not a lower-case word")
        ep.events.append(Event(t, look, dict(show), list(remove), list(say),
                               c.get(ev, "attention", bool, False, w),
                               _locate(c.text, w)))
    ep.events.sort(key=lambda e: e.t)

    if "evaluation" in data:
        ev = data["evaluation"]
        w = ("evaluation",)
        c.keys(ev, ("every", "runs", "steps", "policy"), w)
        ep.evaluation = {"every": c.positive(ev, "every", 10, w),
                         "runs": c.positive(ev, "runs", 5, w),
                         "steps": c.positive(ev, "steps", 100, w),
                         "policy": c.choice(c.get(ev, "policy", str, "behaviour", w),
                                            _EVAL_POLICIES, "evaluation policy",
                                            w + ("policy",))}
    if "naming" in data:
        nm = data["naming"]
        w = ("naming",)
        c.keys(nm, ("executions", "presentations", "confident_after", "max_steps"), w)
        ep.naming = {"executions": c.positive(nm, "executions", 5, w),
                     "presentations": c.positive(nm, "presentations", 40, w),
                     "confident_after": c.positive(nm, "confident_after", 3, w),
                     "max_steps": c.positive(nm, "max_steps", 1000, w)}
    if ep.time_unit == "interaction":
        # interaction cycles are counted by the protocol caregiver
        for i, ph in enumerate(ep.phases):
            if ph.caregiver != "protocol":
                raise c.fail(("phase", i, "caregiver"), 'time_unit = "interaction" counts the '
                             "protocol caregiver's cycles; this phase has caregiver = "
                             f"{ph.caregiver!r}")
        if ep.events:
            raise c.fail(("event", 0), '[[event]] times are control steps; they cannot be used '
                         'with time_unit = "interaction"')
    sp = data.get("speech", {})
    w = ("speech",)
    c.keys(sp, ("say", "voice"), w)
    ep.speech = {"say": c.get(sp, "say", bool, False, w),
                 "voice": c.get(sp, "voice", str, "en", w)}
    return ep


def load_episode(path: str | Path) -> Episode:
    """Read and check the episode script at ``path``.

    Raises:
        EpisodeError: the file is missing or has a problem (``file:line: problem``).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise EpisodeError(f"{path}: no such episode script") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise EpisodeError(f"{path}: cannot read the episode script ({exc})") from None
    return parse_episode(text, path)
