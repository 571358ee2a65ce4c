"""docs/tg.md's table of tg's parameters is checked against the one list of them, the
``learner_parameter/4`` declarations of prolog/tg.pl (as the learner registry reads them):
the same names in the same order, each default, and each default of the worlds where it
differs."""

from __future__ import annotations

import re

from relrl.learners.registry import learner_spec
from tests.conftest import ROOT


def documented() -> list[tuple[str, str]]:
    """``(name, default cell)`` of each row of docs/tg.md's parameter table, in order."""
    text = (ROOT / "docs" / "tg.md").read_text(encoding="utf-8")
    section = text.split("## Parameters", 1)[1]
    return re.findall(r"^\| `(\w+)` \| ([^|]+) \|", section.split("\n\n", 2)[1], re.M)


def defaults_of(cell: str) -> tuple[float, float | None]:
    """The default a table cell gives, and the worlds' when it gives one:
    ``0 (worlds: 0.5)`` is ``(0.0, 0.5)``."""
    m = re.fullmatch(r"\s*([-\d.]+)\s*(?:\(worlds: ([-\d.]+)\))?\s*", cell)
    assert m, f"not a default: {cell!r}"
    return float(m[1]), None if m[2] is None else float(m[2])


def test_the_table_is_the_declarations() -> None:
    spec = learner_spec("tg")
    rows = documented()
    assert [name for name, _ in rows] == [p.name for p in spec.parameters]
    worlds = spec.serves["worlds"]
    for (name, cell), parameter in zip(rows, spec.parameters, strict=True):
        default, in_worlds = defaults_of(cell)
        assert default == parameter.default, f"docs/tg.md: {name} default {cell.strip()}"
        assert in_worlds == worlds.get(name), \
            f"docs/tg.md: {name}'s default in worlds is {worlds.get(name)}, the table says " \
            f"{cell.strip()}"


def test_a_cell_is_read_as_written() -> None:
    assert defaults_of(" 0 (worlds: 0.5) ") == (0.0, 0.5)
    assert defaults_of("1000") == (1000.0, None)
