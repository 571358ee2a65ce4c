"""The paper's metrics, computed from a trace of per-time-unit records.

The simulator appends one :class:`StepRecord` per time unit to ``env.trace`` (the record of
``reset`` first) and also returns it as ``info["record"]``. The metrics read only the fields
named below, so a hand-made trace (or one from a real head) works the same way.

Mutual-gaze events (section 5, "the robot sees the frontal face of the human for 3 units of
time"): a *streak* is a run of consecutive records with ``focus == "centre"`` and
``gaze == "frontal"``; each streak that reaches ``hold`` (3) records counts **one** event,
however long it lasts. Uses ``focus`` and ``gaze``.

Eye contacts in the first N opportunities (Fig. 4): an *opportunity* is a run of records with
the same ``opportunity`` number (the caregiver turns to the robot and waits for eye contact).
Eye contact is *established* in it when, inside it, ``hold`` consecutive records have the
robot on the frontal face. An opportunity counts once it is over (a later number appears) or
established; the last one, still open and not established, is left out. Uses
``opportunity``, ``focus`` and ``gaze``.

Correct gaze index (Eq. 5, after Whalen & Schreibman), in two readings. A *shift from the
human* is a pair of consecutive records where the robot looked at the caregiver's face
(``focus == "centre"``) and then looks anywhere else. It is *correct* when the new focus is
the place the caregiver was looking at (its gaze in the first record: what the robot saw
when it decided).

* **relrl's CGI** (:meth:`GazeMetrics.cgi`) counts only the shifts made while the caregiver
  was looking at a place (``gaze != "frontal"``): a shift while the caregiver looks at the
  robot has no correct location, and counting it as wrong measures eye contact, not gaze
  following.
* **The literal CGI** (:meth:`GazeMetrics.cgi_literal`) is Eq. 5 as written: correct shifts
  over *every* shift from the human, whatever the caregiver was looking at. Looking away
  before the caregiver turns to a toy lowers it.

Both use ``focus`` and ``gaze``; the correct shifts are the same in both.

:class:`GazeMetrics` computes all three in one pass and can be fed record by record, so a
long learning run needs no stored trace.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import NamedTuple

__all__ = [
    "CGI",
    "EyeContacts",
    "GazeMetrics",
    "StepRecord",
    "cgi",
    "cgi_literal",
    "eye_contacts",
    "mutual_gaze_events",
    "summarize",
]

FRONTAL = "frontal"
CENTRE = "centre"


class StepRecord(NamedTuple):
    """What happened in one time unit of the simulator.

    Attributes:
        t: the time unit (0 for the state after ``reset``).
        focus: where the robot's head points (a place name; ``centre`` = the caregiver).
        gaze: where the caregiver looks: ``frontal`` (at the robot) or a place name.
        phase: the caregiver's phase (``engage``, ``present``, ``attend``).
        opportunity: number of the current eye-contact opportunity (from 0).
        trial: number of the current or last toy trial (-1 before the first).
        toys: the toys out, as ``(place, colour)`` pairs, target first.
        target: the target's place, or ``None``.
        attention: the caregiver gives attention in this time unit (the reward).
        contact: eye contact was established in this time unit.
        kinds: the kinds of ``toys``, in the same order (empty when toys have no kind).
    """

    t: int
    focus: str
    gaze: str
    phase: str = "engage"
    opportunity: int = 0
    trial: int = -1
    toys: tuple[tuple[str, str], ...] = ()
    target: str | None = None
    attention: bool = False
    contact: bool = False
    kinds: tuple[str, ...] = ()


class CGI(NamedTuple):
    """A correct gaze index: ``value`` is ``correct / shifts`` (NaN when no shifts)."""

    correct: int
    shifts: int
    value: float


class EyeContacts(NamedTuple):
    """Eye contacts over opportunities.

    Attributes:
        established: opportunities (among those counted) where eye contact was made.
        opportunities: opportunities counted (at most the ``first`` asked for).
        per_opportunity: established or not, for each counted opportunity in order.
    """

    established: int
    opportunities: int
    per_opportunity: tuple[bool, ...]


class GazeMetrics:
    """All the metrics, accumulated one record at a time.

    Example:
        >>> m = GazeMetrics()
        >>> for rec in env.trace:          # doctest: +SKIP
        ...     m.add(rec)
        >>> m.cgi().value, m.mutual_gaze_events, m.eye_contacts(125).established  # doctest: +SKIP
    """

    def __init__(self, hold: int = 3) -> None:
        if hold < 1:
            raise ValueError(f"hold={hold}: use a whole number >= 1")
        self.hold = hold
        #: mutual-gaze events so far.
        self.mutual_gaze_events = 0
        #: shifts from the human while the caregiver looked at a place, and correct ones.
        self.shifts = 0
        self.correct_shifts = 0
        #: every shift from the human, whatever the caregiver looked at (Eq. 5 literally).
        self.all_shifts = 0
        #: per place the caregiver looked at: [correct shifts, shifts] (relrl's CGI by place).
        self.by_place: dict[str, list[int]] = {}
        self._finished: list[bool] = []
        self._streak = 0
        self._prev: StepRecord | None = None
        self._opp: int | None = None
        self._opp_streak = 0
        self._opp_done = False

    def add(self, rec: StepRecord) -> None:
        """Take the next record of the trace."""
        on_face = rec.focus == CENTRE and rec.gaze == FRONTAL
        # mutual gaze: one event per streak reaching `hold`
        self._streak = self._streak + 1 if on_face else 0
        if self._streak == self.hold:
            self.mutual_gaze_events += 1
        # eye contact per opportunity
        if rec.opportunity != self._opp:
            if self._opp is not None:
                self._finished.append(self._opp_done)
            self._opp, self._opp_streak, self._opp_done = rec.opportunity, 0, False
        self._opp_streak = self._opp_streak + 1 if on_face else 0
        if self._opp_streak >= self.hold:
            self._opp_done = True
        # CGI shifts
        prev = self._prev
        if prev is not None and prev.focus == CENTRE and rec.focus != CENTRE:
            self.all_shifts += 1
            if prev.gaze != FRONTAL:
                self.shifts += 1
                counts = self.by_place.setdefault(prev.gaze, [0, 0])
                counts[1] += 1
                if rec.focus == prev.gaze:
                    self.correct_shifts += 1
                    counts[0] += 1
        self._prev = rec

    def extend(self, records: Iterable[StepRecord]) -> GazeMetrics:
        """Take many records; returns ``self``."""
        for rec in records:
            self.add(rec)
        return self

    def cgi(self) -> CGI:
        """relrl's correct gaze index so far (shifts while the caregiver looks at a place)."""
        value = self.correct_shifts / self.shifts if self.shifts else math.nan
        return CGI(self.correct_shifts, self.shifts, value)

    def cgi_literal(self) -> CGI:
        """Eq. 5 read literally: correct shifts over every shift from the human."""
        value = self.correct_shifts / self.all_shifts if self.all_shifts else math.nan
        return CGI(self.correct_shifts, self.all_shifts, value)

    def summary(self, first: int | None = 125) -> dict[str, float | int]:
        """Every metric as a flat, JSON-ready dict (CGIs are NaN without shifts)."""
        c, lit = self.cgi(), self.cgi_literal()
        e = self.eye_contacts(first)
        return {"cgi": c.value, "cgi_literal": lit.value, "correct_shifts": c.correct,
                "shifts": c.shifts, "all_shifts": lit.shifts,
                "mutual_gaze_events": self.mutual_gaze_events,
                "eye_contacts": e.established, "opportunities": e.opportunities}

    def eye_contacts(self, first: int | None = None) -> EyeContacts:
        """Eye contacts in the first ``first`` opportunities (all when ``None``)."""
        flags = list(self._finished)
        if self._opp_done:
            flags.append(True)  # the open opportunity counts once established
        if first is not None:
            flags = flags[:first]
        return EyeContacts(sum(flags), len(flags), tuple(flags))


def cgi(trace: Iterable[StepRecord]) -> CGI:
    """relrl's correct gaze index (Eq. 5) of a trace; see the module documentation."""
    return GazeMetrics().extend(trace).cgi()


def cgi_literal(trace: Iterable[StepRecord]) -> CGI:
    """The correct gaze index of a trace with Eq. 5 read literally (every shift counts)."""
    return GazeMetrics().extend(trace).cgi_literal()


def mutual_gaze_events(trace: Iterable[StepRecord], hold: int = 3) -> int:
    """Mutual-gaze events of a trace: streaks of ``hold`` time units on the frontal face."""
    return GazeMetrics(hold).extend(trace).mutual_gaze_events


def eye_contacts(trace: Iterable[StepRecord], first: int | None = 125, hold: int = 3
                 ) -> EyeContacts:
    """Eye contacts established in the first ``first`` opportunities of a trace."""
    return GazeMetrics(hold).extend(trace).eye_contacts(first)


def summarize(trace: Iterable[StepRecord], hold: int = 3, first: int | None = 125
              ) -> dict[str, float | int]:
    """All metrics of a trace as a flat, JSON-ready dict."""
    return GazeMetrics(hold).extend(trace).summary(first)
