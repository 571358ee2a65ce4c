"""Bounded TOML reading (head/tomlfile.py): nesting is measured before tomllib recurses,
brackets in strings and comments do not count, and only regular files are read."""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

import pytest

from head.tomlfile import MAX_NESTING, read_limited, too_deep

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("text", [
    'x = "' + "[" * 100 + '"\n',
    "x = '" + "{" * 100 + "'\n",
    'x = """\n' + "[" * 100 + '\n"""\n',
    "x = '''\n" + "[" * 100 + "\n'''\n",
    'x = """a\\"""' + "[" * 100 + '"""\n',      # an escaped quote does not end the string
    'x = "a\\"' + "[" * 100 + '"\n',
    "# " + "[" * 100 + "\n",
    "[[phase]]\nsteps = 1\n" * 200,
    "x = " + "[" * MAX_NESTING + "]" * MAX_NESTING + "\n",
    "x = " + "{ a = " * MAX_NESTING + "1" + " }" * MAX_NESTING + "\n",
])
def test_valid_toml_is_not_too_deep_and_parses(text: str) -> None:
    assert too_deep(text) is None
    tomllib.loads(text)


@pytest.mark.parametrize("text, line", [
    ("a = 1\nx = " + "[" * (MAX_NESTING + 1) + "]" * (MAX_NESTING + 1) + "\n", 2),
    ('x = """a""""\n\ny = ' + "[" * 3000, 3),      # the string ends at its last three quotes
    ("x = " + "{ a = " * 3000 + "1" + " }" * 3000, 1),
])
def test_the_line_where_nesting_passes_the_limit(text: str, line: int) -> None:
    assert too_deep(text) == line


def test_every_toml_file_of_the_project_passes() -> None:
    files = [p for p in ROOT.rglob("*.toml") if ".venv" not in p.parts]
    assert len(files) >= 5
    for path in files:
        assert too_deep(path.read_text()) is None, path


def test_only_regular_files_are_read(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "pipe")
    (tmp_path / "dir").mkdir()
    (tmp_path / "ok.toml").write_text("a = 1\n")
    assert read_limited(tmp_path / "ok.toml") == b"a = 1\n"
    with pytest.raises(OSError, match="not a regular file"):
        read_limited(tmp_path / "pipe")               # would block an open() for ever
    with pytest.raises(OSError, match="not a regular file"):
        read_limited("/dev/zero")                     # would read for ever
    with pytest.raises(IsADirectoryError):
        read_limited(tmp_path / "dir")
    with pytest.raises(OSError, match="larger than 3 bytes"):
        read_limited(tmp_path / "ok.toml", limit=3)
    with pytest.raises(OSError, match="NUL"):
        read_limited(str(tmp_path / "a\x00b"))
