"""The learned tree docs/tg.md shows is what ``examples/tg_gaze_following.py`` prints today
(same seed, same numbers): pasted output that no longer matches its command fails here."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT

pytestmark = pytest.mark.slow  # every test here takes a second or more


def test_tg_md_shows_the_tree_the_example_learns(tmp_path: Path) -> None:
    text = (ROOT / "docs" / "tg.md").read_text(encoding="utf-8")
    section = text[text.index("**What tg learned**"):]
    command = re.search(r"\(`examples/tg_gaze_following.py ([^`]*)`", section)
    shown = re.search(r"```text\n(\[1\].*?)```", section, re.S)
    assert command and shown
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "tg_gaze_following.py"),
                           *command[1].split()], capture_output=True, text=True, timeout=600,
                          cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    printed = proc.stdout[proc.stdout.index("[1] "):]
    assert printed.startswith(shown[1].rstrip("\n")), printed
