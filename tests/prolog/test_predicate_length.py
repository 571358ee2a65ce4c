"""No predicate of the knowledge layer runs past about 80 lines (issue 35): a longer one
holds several steps that read better as helper predicates named by what they do."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from tests.conftest import ROOT

LIMIT = 80


def predicate_lines(files: list[str]) -> list[tuple[int, str, str]]:
    """(lines, file, Name/Arity) for every predicate of ``files``, as SWI-Prolog reads them."""
    proc = subprocess.run(
        ["swipl", "-g", "main", "-t", "halt", str(ROOT / "tests" / "prolog" / "predicate_lines.pl"),
         "--", *files], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    rows = []
    for line in proc.stdout.splitlines():
        n, file, pi = line.split(" ", 2)
        rows.append((int(n), file, pi))
    return rows


@pytest.fixture(scope="module")
def rows() -> list[tuple[int, str, str]]:
    assert shutil.which("swipl"), "swipl must be installed (make test installs it)"
    return predicate_lines(sorted(str(p.relative_to(ROOT)) for p in (ROOT / "prolog").glob("*.pl")))


def test_every_file_of_the_knowledge_layer_is_read(rows) -> None:
    files = {file for _, file, _ in rows}
    assert len(files) == len(list((ROOT / "prolog").glob("*.pl")))


def test_no_predicate_is_longer_than_the_limit(rows) -> None:
    long = [f"{file}: {pi} ({n} lines)" for n, file, pi in rows if n > LIMIT]
    assert long == []


def test_a_long_predicate_is_found(tmp_path) -> None:
    body = ",\n".join(f"    X{i} = {i}" for i in range(LIMIT + 1))
    path = tmp_path / "long.pl"
    path.write_text(f"long :-\n{body}.\nshort.\n", encoding="utf-8")
    rows = predicate_lines([str(path)])
    assert sorted((pi, n) for n, _, pi in rows) == [("long/0", LIMIT + 2), ("short/0", 1)]
