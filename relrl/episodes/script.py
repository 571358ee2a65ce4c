"""Episode scripts: TOML files that script a caregiver, a world and a learner over time.

:func:`load_episode` reads and checks a script and returns an :class:`Episode`. Every problem
is a line ``file:line: problem`` and one :class:`EpisodeError` lists them all; syntax errors
come from ``tomllib`` (which gives the line, and stops at the first), problems of meaning (an
unknown key, a place that does not exist, a negative number of steps) are located by finding
the key's line in the text, through an index built once, so checking is linear in the length
of the script.

See ``docs/episodes.md`` for the format, with examples.
"""

from __future__ import annotations

import difflib
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any

from head.tomlfile import MAX_NESTING, read_limited, too_deep
from perception.vocabulary import OBJECT_PLACES, PLACES
from relrl.episodes.outputs import policy_save_problem
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
    """Problems in an episode script, one ``file:line: problem`` line each.

    Attributes:
        problems: every problem found (the message lists the first :data:`MAX_LISTED`).
    """

    def __init__(self, message: str, problems: list[str] | None = None) -> None:
        super().__init__(message)
        self.problems = problems or [message]


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
#: a key at the start of a line (``name =``, ``"quoted name" =``): what comes before ``=``
_KEY = re.compile(r"^\s*([^\s=][^=]*?)\s*=")
#: the most evaluation runs per point, and naming executions, a script may ask for.
MAX_RUNS = 10_000
#: problems listed in full before the rest are counted.
MAX_LISTED = 20
#: names in --out that belong to the run itself (a policy may not take them).
class _Lines:
    """Where each table header and key is in the text, indexed once (linear in the text)."""

    def __init__(self, text: str) -> None:
        self.lines = text.splitlines()
        self.headers: dict[str, list[int]] = {}
        starts = []
        for i, line in enumerate(self.lines):
            m = _HEADER.match(line)
            if m:
                self.headers.setdefault(m.group(2), []).append(i)
                starts.append(i)
        self.section_end = dict(zip(starts, [*starts[1:], len(self.lines)], strict=False))
        #: each section's keys -> their first line (0-based), made when first asked for
        self._keys: dict[int, dict[str, int]] = {}
        #: lines examined by :meth:`locate` (checking stays linear in the text)
        self.scanned = 0

    def locate(self, path: tuple[str | int, ...]) -> int:
        """The 1-based line of the key at ``path`` (table, [array index], key...); best effort:
        the table's header when the key is not found, line 1 when the table is not."""
        index = path[1] if len(path) > 1 and isinstance(path[1], int) else 0
        rest = [p for p in path[1:] if not isinstance(p, int)]
        starts = self.headers.get(str(path[0]), [])
        if index >= len(starts):
            return 1
        start = starts[index]
        if rest:
            line = self._section_keys(start).get(str(rest[0]))
            if line is not None:
                return line + 1
        return start + 1

    def _section_keys(self, start: int) -> dict[str, int]:
        """The keys of the section whose header is on line ``start`` (scanned once)."""
        keys = self._keys.get(start)
        if keys is None:
            keys = {}
            for j in range(start + 1, self.section_end[start]):
                self.scanned += 1
                m = _KEY.match(self.lines[j])
                if m:
                    keys.setdefault(m.group(1), j)
            self._keys[start] = keys
        return keys


class _Checker:
    """Reads values out of the parsed TOML and collects every located problem."""

    def __init__(self, path: Path, text: str) -> None:
        self.path = path
        self.where = _Lines(text)
        self.problems: list[tuple[int, str]] = []

    def fail(self, where: tuple[str | int, ...], problem: str) -> None:
        """Record a problem at the key ``where``; checking goes on."""
        line = self.where.locate(where)
        self.problems.append((line, f"{self.path}:{line}: {problem}"))

    def raise_problems(self) -> None:
        """Raise one :class:`EpisodeError` listing every problem in line order (if any)."""
        if not self.problems:
            return
        problems = [text for _, text in sorted(self.problems, key=lambda p: p[0])]
        shown = problems[:MAX_LISTED]
        if len(problems) > MAX_LISTED:
            shown.append(f"... and {len(problems) - MAX_LISTED} more")
        if len(problems) > 1:
            shown.append(f"{len(problems)} problems in {self.path}")
        raise EpisodeError("\n".join(shown), problems)

    def keys(self, table: dict[str, Any], allowed: tuple[str, ...], where: tuple) -> None:
        for key in table:
            if key not in allowed:
                close = difflib.get_close_matches(key, allowed, n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else \
                    f" (known: {', '.join(allowed)})"
                self.fail(where + (key,), f"unknown key {key!r} in [{where[0]}]{hint}")

    def get(self, table: dict[str, Any], key: str, kind: type | tuple, default: Any,
            where: tuple) -> Any:
        """``table[key]`` when it has the type ``kind`` (a float must be finite); else the
        problem is recorded and ``default`` returned."""
        if key not in table:
            return default
        value = table[key]
        ok = isinstance(value, kind) and not (isinstance(value, bool) and kind in (int, float))
        if kind is float and isinstance(value, int) and not isinstance(value, bool):
            ok, value = True, float(value)
        if not ok:
            name = kind.__name__ if isinstance(kind, type) else "/".join(k.__name__ for k in kind)
            self.fail(where + (key,), f"{key} must be a {name}, not {value!r}")
            return default
        if isinstance(value, float) and not math.isfinite(value):
            self.fail(where + (key,), f"{key} must be a finite number, not {value!r}")
            return default
        return value

    def positive(self, table: dict[str, Any], key: str, default: int, where: tuple,
                 minimum: int = 1, maximum: int | None = None) -> int:
        value = self.get(table, key, int, default, where)
        if value < minimum or (maximum is not None and value > maximum):
            bound = f"at least {minimum}" if maximum is None else \
                f"from {minimum} to {maximum}"
            self.fail(where + (key,), f"{key} must be {bound}, not {value}")
            return default
        return value

    def choice(self, value: str, choices: tuple[str, ...], what: str, where: tuple) -> bool:
        """Whether ``value`` is one of ``choices`` (recording the problem when not)."""
        if value in choices:
            return True
        close = difflib.get_close_matches(str(value), choices, n=1)
        hint = f"did you mean {close[0]!r}?" if close else f"use one of {', '.join(choices)}"
        self.fail(where, f"unknown {what} {value!r}; {hint}")
        return False

    def table(self, data: dict[str, Any], key: str) -> dict[str, Any]:
        """A top-level table (a problem and ``{}`` when it is something else)."""
        value = data.get(key, {})
        if not isinstance(value, dict):
            self.fail((key,), f"{key} must be a table [{key}], not {value!r}")
            return {}
        return value

    def policy_file(self, value: str, where: tuple) -> str | None:
        """A policy file name to write inside the run's output folder, or None when bad."""
        parts = PurePosixPath(value.replace("\\", "/"))
        if value.endswith(("/", "\\")) or parts.is_absolute() or Path(value).is_absolute() \
                or ".." in parts.parts or value in (".", ""):
            self.fail(where, f"policy_save must be a file name inside --out (a relative path "
                             f"without '..'), not {value!r}")
            return None
        if problem := policy_save_problem(str(parts)):
            self.fail(where, problem)
            return None
        return str(parts)


_TOP = ("episode", "learner", "world", "caregiver", "phase", "event", "evaluation", "naming",
        "speech")


def parse_episode(text: str, path: str | Path = "<episode>") -> Episode:
    """Parse and check an episode script given as text (``path`` names it in errors).

    Raises:
        EpisodeError: every problem of the script, one ``file:line: problem`` line each (a
            TOML syntax error stops at the first).
    """
    path = Path(path)
    deep = too_deep(text)
    if deep is not None:
        raise EpisodeError(f"{path}:{deep}: arrays or inline tables nested more than "
                           f"{MAX_NESTING} deep")
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
            c.fail((key,), f"unknown table [{key}]{hint}")
    ep = Episode(path=path)
    _episode_table(c, c.table(data, "episode"), ep)
    _learner_table(c, c.table(data, "learner"), ep)
    _world_table(c, c.table(data, "world"), ep)
    _caregiver_table(c, c.table(data, "caregiver"), ep)
    before = len(c.problems)
    _phases(c, data.get("phase", []), ep)
    # a bad phase length would make every later event look late: say so only once
    _events(c, data.get("event", []), ep, check_end=len(c.problems) == before)
    _optional_tables(c, data, ep)
    c.raise_problems()
    return ep


def _episode_table(c: _Checker, head: dict[str, Any], ep: Episode) -> None:
    w = ("episode",)
    base = ep.path.parent
    c.keys(head, ("name", "domain", "seed", "learner", "policy_load", "policy_save",
                  "time_unit"), w)
    ep.name = c.get(head, "name", str, ep.path.stem, w)
    domain = c.get(head, "domain", str, None, w)
    if domain is None:
        c.fail(w, "[episode] needs domain = \"path/to/domain.pl\"")
    elif "\0" in domain:
        c.fail(w + ("domain",), f"domain {domain!r} holds a NUL character; no file name can")
    else:
        ep.domain = (base / domain).resolve()
        if not ep.domain.is_file():
            c.fail(w + ("domain",), f"domain file {domain!r} not found (looked for "
                   f"{ep.domain})")
    ep.seed = c.get(head, "seed", int, 0, w)
    if ep.seed < 0:
        c.fail(w + ("seed",), f"seed must be an integer >= 0, not {ep.seed}")
        ep.seed = 0
    ep.learner = c.get(head, "learner", str, "etg", w)
    from relrl.learners import DOMAINS, learners

    if not c.choice(ep.learner, learners(DOMAINS), "learner", w + ("learner",)):
        ep.learner = ""
    load = c.get(head, "policy_load", str, "", w)
    if "\0" in load:
        c.fail(w + ("policy_load",), f"policy_load {load!r} holds a NUL character; no file "
                                     "name can")
    elif load:
        ep.policy_load = (base / load).resolve()
        if not ep.policy_load.is_file():
            what = ("is a folder, not a policy file" if ep.policy_load.is_dir() else
                    "is not a regular file (a device, a pipe or a socket)"
                    if ep.policy_load.exists() else "not found")
            c.fail(w + ("policy_load",), f"policy file {load!r} {what}")
    save = c.get(head, "policy_save", str, "policy.pl", w)
    ep.policy_save = c.policy_file(save, w + ("policy_save",)) if save else None
    unit = c.get(head, "time_unit", str, "step", w)
    if c.choice(unit, TIME_UNITS, "time unit", w + ("time_unit",)):
        ep.time_unit = unit


def _learner_table(c: _Checker, params: dict[str, Any], ep: Episode) -> None:
    ok = True
    for key, value in params.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value):
            c.fail(("learner", key), f"learner parameter {key} must be a finite number, "
                   f"not {value!r}")
            ok = False
            continue
        ep.learner_params[key] = float(value)
    if not (ok and ep.learner):
        return
    from relrl.errors import ConfigError
    from relrl.learners import make_learner

    try:
        make_learner(ep.learner, **ep.learner_params)
    except ConfigError as exc:
        bad = [k for k in params if re.search(rf"\b{re.escape(k)}\b", str(exc))]
        c.fail(("learner", bad[0]) if bad else ("learner",), str(exc))


def _world_table(c: _Checker, world: dict[str, Any], ep: Episode) -> None:
    w = ("world",)
    c.keys(world, ("perception", "variation", "lighting", "fruits", "names", "places"), w)
    mode = c.get(world, "perception", str, "render", w)
    if c.choice(mode, _PERCEPTION, "perception mode", w + ("perception",)):
        ep.perception = mode
    variation = c.get(world, "variation", str, "none", w)
    if c.choice(variation, _VARIATION, "appearance variation", w + ("variation",)):
        ep.variation = variation
    light = c.get(world, "lighting", (float, int, list), [0.9, 1.1], w)
    light = [light, light] if not isinstance(light, list) else light
    if len(light) != 2 or not all(isinstance(x, (int, float)) and 0.05 <= x <= 3.0
                                  for x in light) or light[0] > light[1]:
        c.fail(w + ("lighting",), f"lighting must be a number or [low, high] within "
               f"0.05..3.0, not {world.get('lighting')!r}")
    else:
        ep.lighting = (float(light[0]), float(light[1]))
    fruits = c.get(world, "fruits", list, list(ep.fruits), w)
    if all([c.choice(kind, _KINDS, "object", w + ("fruits",)) for kind in fruits]) and fruits:
        ep.fruits = tuple(fruits)
    elif not fruits:
        c.fail(w + ("fruits",), "fruits must name at least one object")
    names = c.get(world, "names", dict, {}, w)
    for kind, word in names.items():
        if not isinstance(word, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", word):
            c.fail(w + ("names",), f"the name of {kind} must be a lower-case word, "
                   f"not {word!r}")
    ep.names = {k: v for k, v in names.items() if isinstance(v, str)}
    places = c.get(world, "places", list, list(OBJECT_PLACES), w)
    if all([c.choice(p, OBJECT_PLACES, "object place", w + ("places",)) for p in places]) \
            and places:
        ep.places = tuple(places)
    elif not places:
        c.fail(w + ("places",), "places must name at least one place")


def _caregiver_table(c: _Checker, care: dict[str, Any], ep: Episode) -> None:
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


def _phases(c: _Checker, phases: Any, ep: Episode) -> None:
    if not isinstance(phases, list) or not phases or \
            not all(isinstance(ph, dict) for ph in phases):
        c.fail(("phase",), "the script needs at least one [[phase]] with steps = N")
        return
    for i, ph in enumerate(phases):
        w = ("phase", i)
        c.keys(ph, ("name", "steps", "caregiver", "objects", "learning"), w)
        if "steps" not in ph:
            c.fail(w, f"[[phase]] number {i + 1} needs steps = N")
        caregiver = c.get(ph, "caregiver", str, "protocol", w)
        if not c.choice(caregiver, _CAREGIVERS, "caregiver", w + ("caregiver",)):
            caregiver = "protocol"
        ep.phases.append(Phase(
            name=c.get(ph, "name", str, f"phase {i + 1}", w),
            steps=c.positive(ph, "steps", 1, w), caregiver=caregiver,
            objects=c.get(ph, "objects", bool, True, w),
            learning=c.get(ph, "learning", bool, True, w)))


def _events(c: _Checker, events: Any, ep: Episode, *, check_end: bool) -> None:
    if not isinstance(events, list) or not all(isinstance(ev, dict) for ev in events):
        c.fail(("event",), "events must be [[event]] tables")
        return
    last = ep.steps
    for i, ev in enumerate(events):
        w = ("event", i)
        c.keys(ev, ("t", "look", "show", "remove", "say", "attention"), w)
        if "t" not in ev:
            c.fail(w, "[[event]] needs t = TIME_UNIT")
        t = c.positive(ev, "t", 1, w)
        if check_end and t > last:
            c.fail(w + ("t",), f"t = {t} is after the last time unit ({last})")
        look = c.get(ev, "look", str, None, w)
        if look is not None and not c.choice(look, PLACES, "place", w + ("look",)):
            look = None
        show = c.get(ev, "show", dict, {}, w)
        show = {place: kind for place, kind in show.items()
                if c.choice(place, OBJECT_PLACES, "object place", w + ("show",))
                and c.choice(kind, _KINDS, "object", w + ("show",))}
        remove = c.get(ev, "remove", (list, str), [], w)
        remove = [remove] if isinstance(remove, str) else remove
        remove = [p for p in remove
                  if c.choice(p, OBJECT_PLACES + ("all",), "place", w + ("remove",))]
        say = c.get(ev, "say", (list, str), [], w)
        say = say.split() if isinstance(say, str) else say
        for word in say:
            if not isinstance(word, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", word):
                c.fail(w + ("say",), f"say: {word!r} is not a lower-case word")
        ep.events.append(Event(t, look, dict(show), list(remove),
                               [x for x in say if isinstance(x, str)],
                               c.get(ev, "attention", bool, False, w), c.where.locate(w)))
    ep.events.sort(key=lambda e: e.t)


def _optional_tables(c: _Checker, data: dict[str, Any], ep: Episode) -> None:
    if "evaluation" in data:
        ev = c.table(data, "evaluation")
        w = ("evaluation",)
        c.keys(ev, ("every", "runs", "steps", "policy"), w)
        ep.evaluation = {"every": c.positive(ev, "every", 10, w),
                         "runs": c.positive(ev, "runs", 5, w, maximum=MAX_RUNS),
                         "steps": c.positive(ev, "steps", 100, w),
                         "policy": "behaviour"}
        policy = c.get(ev, "policy", str, "behaviour", w)
        if c.choice(policy, _EVAL_POLICIES, "evaluation policy", w + ("policy",)):
            ep.evaluation["policy"] = policy
    if "naming" in data:
        nm = c.table(data, "naming")
        w = ("naming",)
        c.keys(nm, ("executions", "presentations", "confident_after", "max_steps"), w)
        ep.naming = {"executions": c.positive(nm, "executions", 5, w, maximum=MAX_RUNS),
                     "presentations": c.positive(nm, "presentations", 40, w),
                     "confident_after": c.positive(nm, "confident_after", 3, w),
                     "max_steps": c.positive(nm, "max_steps", 1000, w)}
    if ep.time_unit == "interaction":
        # interaction cycles are counted by the protocol caregiver
        for i, ph in enumerate(ep.phases):
            if ph.caregiver != "protocol":
                c.fail(("phase", i, "caregiver"), 'time_unit = "interaction" counts the '
                       "protocol caregiver's cycles; this phase has caregiver = "
                       f"{ph.caregiver!r}")
        if ep.events:
            c.fail(("event", 0), '[[event]] times are control steps; they cannot be used '
                   'with time_unit = "interaction"')
    sp = c.table(data, "speech")
    w = ("speech",)
    c.keys(sp, ("say", "voice"), w)
    ep.speech = {"say": c.get(sp, "say", bool, False, w),
                 "voice": c.get(sp, "voice", str, "en", w)}


def load_episode(path: str | Path) -> Episode:
    """Read and check the episode script at ``path``.

    Raises:
        EpisodeError: the file is missing or has a problem (``file:line: problem``).
    """
    path = Path(path)
    if path.is_dir():
        raise EpisodeError(f"{path}: is a folder, not an episode script (.toml)")
    try:
        raw = read_limited(path)
    except FileNotFoundError:
        raise EpisodeError(f"{path}: no such episode script") from None
    except OSError as exc:
        raise EpisodeError(f"{path}: cannot read the episode script ({exc.strerror or exc})") \
            from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise EpisodeError(f"{path}:{line}: not UTF-8 text (byte {raw[exc.start]:#04x}); "
                           "save the script as UTF-8") from None
    return parse_episode(text, path)
