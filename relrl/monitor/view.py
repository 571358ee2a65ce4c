"""One time unit of a session as the monitor and the recording see it.

:class:`StepView` is the record the live monitor shows, the recorded trace holds one line of
(``trace.jsonl``), and replay reads back. It is filled from the control loop's
:class:`~relrl.loop.StepRecord` (:func:`view_of`) with plain, JSON-ready values: terms as
Prolog text, the learner's explanation as a dict.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from relrl.terms import format_term

__all__ = ["StepView", "head_view", "metrics_view", "overlay_of", "view_of"]

#: a hobby servo's nominal angle per microsecond of pulse width (90 degrees over 1000 us);
#: used only to show an approximate angle beside the commanded pulse widths.
NOMINAL_DEG_PER_US = 0.09


@dataclass
class StepView:
    """What happened in one time unit (every field JSON-ready).

    Attributes:
        t: the time unit (from 1).
        phase: the script's phase.
        percepts: this unit's percepts, as Prolog text.
        memory: working memory as ``[age, element]`` pairs, youngest first (``None`` when not
            asked for in this unit).
        memory_size: the number of elements in working memory (``None`` when not known).
        state: the state code.
        necessity: the active necessity, or ``None``.
        activation: every necessity unit's output.
        reward: the reward for the previous response.
        response: the chosen response as text, or ``None``.
        allowed: the responses allowed now.
        explanation: the learner's explanation (path of tests, ranked actions), or ``None``.
        head: the head's commanded pose (``None`` without a head).
        metrics: running CGI, shifts, eye contacts and opportunities.
        extra: what the session adds (caregiver, focus, heard, naming, said, frame, ...).
    """

    t: int
    phase: str
    percepts: list[str]
    memory: list[list[Any]] | None
    memory_size: int | None
    state: int
    necessity: str | None
    activation: dict[str, float]
    reward: float
    response: str | None
    allowed: list[str]
    explanation: dict[str, Any] | None = None
    head: dict[str, Any] | None = None
    metrics: dict[str, Any] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)

    def row(self) -> dict[str, Any]:
        """A flat JSON-ready dict (the trace line): the fields, then :attr:`extra`."""
        out = asdict(self)
        extra = out.pop("extra")
        out.update(extra)
        return out


def _text(term: Any) -> str | None:
    return None if term is None else format_term(term)


def _finite(x: float) -> float | None:
    return None if isinstance(x, float) and not math.isfinite(x) else x


def view_of(t: int, phase: str, record: Any, *, memory: list[tuple[int, Any]] | None = None,
            explanation: dict[str, Any] | None = None) -> StepView:
    """A :class:`StepView` from a control-loop record (``record.out`` is the step's output).

    Args:
        t: the session's time unit.
        phase: the phase name.
        record: a :class:`relrl.loop.StepRecord`.
        memory: working memory as ``(age, element)`` pairs, when known.
        explanation: the learner's explanation of this step, when known.
    """
    out = record.out
    mem = getattr(out, "memory", None) if memory is None else memory
    exp = getattr(out, "explanation", None) if explanation is None else explanation
    size = getattr(out, "memory_size", None)
    if size is None and mem is not None:
        size = len(mem)
    return StepView(
        t=t, phase=phase,
        percepts=[format_term(p) for p in record.percepts],
        memory=None if mem is None else [[int(a), format_term(e)] for a, e in mem],
        memory_size=size,
        state=int(out.code),
        necessity=None if out.necessity in (None, "none") else str(out.necessity),
        activation={k: round(float(v), 6) for k, v in out.outputs.items()},
        reward=float(out.reward),
        response=_text(out.action),
        allowed=[format_term(a) for a in out.allowed],
        explanation=exp,
    )


def head_view(head: Any, looking_at: str | None = None) -> dict[str, Any] | None:
    """The commanded pose of a :class:`head.Head` (``None`` for no head): per servo the
    pulse width in microseconds, its offset from the calibrated centre and the nominal angle
    (:data:`NOMINAL_DEG_PER_US`), and where the head looks (as the world knows it: asking
    a serial head would cost a round trip on the wire)."""
    if head is None:
        return None
    servos = head.calibration.servos
    pose = {}
    for name, us in head.targets.items():
        offset = int(us) - servos[name].centre
        pose[name] = {"us": int(us), "offset_us": offset,
                      "deg": round(offset * NOMINAL_DEG_PER_US, 1)}
    return {"servos": pose, "looking_at": looking_at, "clamped": head.clamped_count}


def metrics_view(metrics: Any) -> dict[str, Any]:
    """Running CGI and eye contacts of a :class:`relrl.sim.metrics.GazeMetrics`."""
    c = metrics.cgi()
    e = metrics.eye_contacts()
    return {"cgi": _finite(c.value), "correct_shifts": c.correct, "shifts": c.shifts,
            "eye_contacts": e.established, "opportunities": e.opportunities}


def overlay_of(percept: Any, frame: Any) -> dict[str, Any] | None:
    """What perception found in a frame, for drawing over it: the face (box, pose, pan,
    tilt), the most salient area (box, saliency peak and where it is) with its colour and
    place; ``None`` without a percept."""
    if percept is None or frame is None:
        return None
    h, w = frame.shape[:2]
    out: dict[str, Any] = {"width": int(w), "height": int(h), "face": None, "object": None}
    face = percept.face
    if face is not None:
        out["face"] = {"box": [int(v) for v in face.box], "pose": face.pose,
                       "pan": round(float(face.pan), 1), "tilt": round(float(face.tilt), 1),
                       "detector": face.detector}
    area = percept.area
    if area is not None:
        colour = percept.colour
        out["object"] = {
            "box": [int(v) for v in area.box], "peak": [int(v) for v in area.centre],
            "saliency": round(float(area.peak), 3), "place": percept.place,
            "colour": None if colour is None else colour.name,
            "rgb": None if colour is None else [int(colour.r), int(colour.g), int(colour.b)],
        }
    return out
