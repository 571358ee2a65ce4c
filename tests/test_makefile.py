"""``make`` installs the Debian packages relrl needs only when they are missing, and without
their recommended packages (run against a stand-in apt-get that records its arguments)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _make_swipl(tmp_path: Path, present: tuple[str, ...]) -> list[str]:
    make = shutil.which("make")
    if make is None:
        pytest.fail("make is not installed")
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    log = tmp_path / "apt.log"
    (bin_dir / "apt-get").write_text(f'#!/bin/sh\necho "$@" >> {log}\n')
    for name in present:
        (bin_dir / name).write_text("#!/bin/sh\n")
    for f in bin_dir.iterdir():
        f.chmod(0o755)
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS")}
    env["PATH"] = str(bin_dir)   # the recipe finds only the stand-ins
    proc = subprocess.run([make, "-s", "-C", str(ROOT), "swipl"], env=env, capture_output=True,
                          text=True, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return log.read_text().splitlines() if log.exists() else []


def test_missing_packages_are_installed_without_recommends(tmp_path: Path) -> None:
    calls = _make_swipl(tmp_path, present=())
    assert calls == ["update -qq",
                     "install -y -qq --no-install-recommends swi-prolog-nox espeak-ng graphviz "
                     "chromium libportaudio2"]


def test_only_what_is_missing(tmp_path: Path) -> None:
    assert _make_swipl(tmp_path, present=("swipl", "dot", "dpkg")) == [
        "update -qq", "install -y -qq --no-install-recommends espeak-ng chromium"]


def test_nothing_when_everything_is_there(tmp_path: Path) -> None:
    # dot: graphviz; dpkg answers that libportaudio2 is installed (the stand-in says yes)
    assert _make_swipl(tmp_path, present=("swipl", "espeak-ng", "dot", "chromium", "dpkg")) == []
