"""What a recorded session's files must hold for replay, checked as a whole before serving.

A recording is data from disk: written by ``relrl run --record``, or by anything else. Replay
reads each line against the shapes below once, at start, so the server and the page never
meet a value of an unexpected type: a wrong one is one line naming the file, the line and the
field (``trace.jsonl:12: activation.socialize must be a number, not 'high'``), exit 2.

Shapes (:func:`check`): ``"int"`` a whole number, ``"num"`` a number, ``"str"`` text, ``"key"``
text or a whole number, ``"any"`` any JSON; ``[SHAPE]`` a list of them; ``("map", SHAPE)`` an
object whose every value is one; ``{"field": SHAPE}`` an object with these fields (others
kept as they are; a field named ``"name!"`` must be there and not ``null``, one named
``"name?"`` must be there). Every other value may be ``null``, but objects and lists inside a
list or a map (the page walks them).
Numbers that are not finite (``NaN``, ``Infinity``, ``1e400``; ``relrl run`` writes NaN when a
policy's Q is NaN) are ``null`` where a number is expected; elsewhere the server says them as
``null`` (:func:`finite`): JSON has no NaN, and a browser cannot plot it. Parse with
:func:`loads`, which keeps the spelling of ``NaN`` and ``Infinity`` for messages.
"""

from __future__ import annotations

import json
import math
from typing import Any

__all__ = ["EVENT", "FRAME", "MANIFEST", "SUMMARY", "TRACE_ROW", "TREE_ROW", "ShapeError",
           "check", "finite", "loads"]

_EXPLANATION = {"learner": "any", "state": "any", "necessity": "any", "leaf": "any",
                "path": [{"test": "any", "holds": "any"}],
                "ranked": [{"response": "any", "q": "num", "fitness": "num", "value": "num"}]}
_OVERLAY = {"width": "num", "height": "num",
            "face": {"box!": ["num"], "pan": "num", "tilt": "num"},
            "object": {"box!": ["num"], "peak!": ["num"], "saliency": "num", "rgb": ["num"]}}
#: one line of ``trace.jsonl`` (a :class:`~relrl.monitor.view.StepView` row).
TRACE_ROW: dict[str, Any] = {
    "t!": "int", "unit": "int", "phase": "any", "percepts": ["any"], "memory": [["any"]],
    "memory_size": "int", "state": "any", "necessity": "any", "activation": ("map", "num"),
    "reward": "num", "response": "any", "allowed": ["any"], "explanation": _EXPLANATION,
    "head": {"servos": ("map", {"us": "num", "offset_us": "num", "deg": "num"}),
             "clamped": "num"},
    "metrics": {"cgi": "num", "correct_shifts": "num", "shifts": "num",
                "eye_contacts": "num", "opportunities": "num"},
    "caregiver": {"objects": ("map", "any")}, "heard": ["any"], "frame": "int",
    "overlay": _OVERLAY}
#: one line of ``frames.jsonl``.
FRAME: dict[str, Any] = {"index!": "int", "t!": "int"}
#: one line of ``trees.jsonl``: the learner's tree from time unit ``t`` on.
TREE_ROW: dict[str, Any] = {
    "t!": "int", "graph?": {"nodes!": [{"id!": "key", "kind": "str"}],
                            "edges": [{"from!": "key", "to!": "key"}]}}
#: one line of ``events.jsonl``.
EVENT: dict[str, Any] = {"t": "int", "cgi_mean": "num", "cgi_std": "num"}
#: ``session.json``: what replay shows of it.
MANIFEST: dict[str, Any] = {"learner": {"name": "any"}, "necessities": ["str"],
                            "responses": ["any"], "recording": "any"}
#: ``summary.json``: what replay shows of it.
SUMMARY: dict[str, Any] = {"learner": {"name": "any"}}

class _Constant(float):
    """``NaN``, ``Infinity`` or ``-Infinity`` as read, so a message can say which."""

    def __new__(cls, text: str) -> _Constant:
        value = super().__new__(cls, text)
        value.text = text  # type: ignore[attr-defined]
        return value

    def __repr__(self) -> str:
        return self.text  # type: ignore[attr-defined,no-any-return]


def loads(text: str | bytes) -> Any:
    """``json.loads`` that keeps ``NaN`` and ``Infinity`` as they were written."""
    return json.loads(text, parse_constant=_Constant)


_SAID = {"int": "a whole number", "num": "a number", "str": "text",
         "key": "text or a whole number"}
_SCALARS = {"int": (int,), "num": (int, float), "str": (str,), "key": (int, str)}


class ShapeError(ValueError):
    """A value of the wrong shape: where it is (``explanation.ranked[2].q``), what it must
    be, and what it is."""

    def __init__(self, must: str | None, value: Any = None) -> None:
        super().__init__(must)
        self.must, self.value, self.place = must, value, ""

    def at(self, part: str) -> ShapeError:
        """The same error one level up (``part`` is a field name or ``[i]``)."""
        self.place = part + ("" if not self.place or self.place.startswith("[")
                             else ".") + self.place
        return self

    def __str__(self) -> str:
        where = self.place or "the line"
        if self.must is None:
            return f"{where} is missing"
        value = self.value
        shown = repr(value) if isinstance(value, float) else \
            json.dumps(value, ensure_ascii=False, default=repr)
        shown = shown if len(shown) <= 40 else shown[:37] + "..."
        return f"{where} must be {self.must}, not {shown}"


def _any(value: Any) -> Any:
    return value


def _compile(shape: Any, null: bool) -> Any:
    """A function checking one value against ``shape`` (raises :class:`ShapeError`)."""
    if shape == "any":
        return _any
    if isinstance(shape, str):
        kinds, must, number = _SCALARS[shape], _SAID[shape], shape == "num"

        def scalar(value: Any) -> Any:
            if isinstance(value, kinds) and not isinstance(value, bool):
                if isinstance(value, float) and not math.isfinite(value):
                    if number and null:
                        return None
                    raise ShapeError(must, value)
                return value
            if value is None and null:
                return None
            raise ShapeError(must, value)

        return scalar
    if isinstance(shape, list):
        item = _compile(shape[0], null=isinstance(shape[0], str))

        def listed(value: Any) -> Any:
            if type(value) is not list:
                if value is None and null:
                    return None
                raise ShapeError("a list", value)
            if item is _any:
                return value
            out = value
            for i, x in enumerate(value):
                try:
                    y = item(x)
                except ShapeError as exc:
                    raise exc.at(f"[{i}]") from None
                if y is not x:
                    out = list(value) if out is value else out
                    out[i] = y
            return out

        return listed
    if isinstance(shape, tuple):  # ("map", SHAPE)
        each = _compile(shape[1], null=isinstance(shape[1], str))
        fields = None
    else:
        each = None
        fields = [(name.rstrip("!?"), _compile(inner, null=not name.endswith("!")),
                   name.endswith(("!", "?"))) for name, inner in shape.items()]

    def obj(value: Any) -> Any:
        if type(value) is not dict:
            if value is None and null:
                return None
            raise ShapeError("an object", value)
        out = value
        checks = fields if fields is not None else [(k, each, False) for k in value]
        for key, check_one, required in checks:
            if key not in value:
                if required:
                    raise ShapeError(None).at(key)
                continue
            x = value[key]
            try:
                y = check_one(x)
            except ShapeError as exc:
                raise exc.at(key) from None
            if y is not x:
                out = dict(value) if out is value else out
                out[key] = y
        return out

    return obj


_COMPILED: dict[tuple[int, bool], Any] = {}


def check(value: Any, shape: Any, *, null: bool = True) -> Any:
    """``value`` checked against ``shape`` (see the module's text), with numbers that are not
    finite replaced by ``None`` where a number is expected (``value`` itself is returned
    when nothing was replaced).

    Raises:
        ShapeError: a value of the wrong shape.
    """
    key = (id(shape), null)
    if key not in _COMPILED:
        _COMPILED[key] = (_compile(shape, null), shape)  # the shape kept: its id stays
    return _COMPILED[key][0](value)


def finite(value: Any) -> Any:
    """``value`` with every float that is not finite replaced by ``None`` (JSON has no
    NaN)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [finite(v) for v in value]
    return value
