"""``make`` installs what each job needs, and only what is missing: the demo SWI-Prolog and the
runtime with its plots; the tests also their Debian packages and extras. Debian packages come
without their recommended packages (run against a stand-in apt-get that records its
arguments); pip's extras per job are read off ``make -n`` (what make would run)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _make() -> str:
    make = shutil.which("make")
    if make is None:
        pytest.fail("make is not installed")
    return make


def _make_debs(tmp_path: Path, target: str, present: tuple[str, ...]) -> list[str]:
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(parents=True)
    log = tmp_path / "apt.log"
    (bin_dir / "apt-get").write_text(f'#!/bin/sh\necho "$@" >> {log}\n')
    for name in present:
        (bin_dir / name).write_text("#!/bin/sh\n")
    for f in bin_dir.iterdir():
        f.chmod(0o755)
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS")}
    env["PATH"] = str(bin_dir)   # the recipe finds only the stand-ins
    proc = subprocess.run([_make(), "-s", "-C", str(ROOT), target], env=env,
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return log.read_text().splitlines() if log.exists() else []


def test_test_packages_are_installed_without_recommends(tmp_path: Path) -> None:
    calls = _make_debs(tmp_path, "debs-test", present=())
    assert calls == ["update -qq",
                     "install -y -qq --no-install-recommends swi-prolog-nox espeak-ng graphviz "
                     "chromium libportaudio2"]


def test_the_demo_needs_only_swi_prolog(tmp_path: Path) -> None:
    calls = _make_debs(tmp_path, "debs-demo", present=())
    assert calls == ["update -qq", "install -y -qq --no-install-recommends swi-prolog-nox"]


def test_only_what_is_missing(tmp_path: Path) -> None:
    assert _make_debs(tmp_path, "debs-test", present=("swipl", "dot", "dpkg")) == [
        "update -qq", "install -y -qq --no-install-recommends espeak-ng chromium"]


def test_nothing_when_everything_is_there(tmp_path: Path) -> None:
    # dot: graphviz; dpkg answers that libportaudio2 is installed (the stand-in says yes)
    assert _make_debs(tmp_path, "debs-test",
                      present=("swipl", "espeak-ng", "dot", "chromium", "dpkg")) == []
    assert _make_debs(tmp_path / "demo", "debs-demo", present=("swipl",)) == []


def _pip_extras(target: str) -> set[str]:
    """The extras ``make -n TARGET`` would install, as if the environment were new."""
    proc = subprocess.run([_make(), "-n", "-B", "-C", str(ROOT), target], capture_output=True,
                          text=True, check=True)
    found = re.findall(r"pip install -q -e '\.\[([^\]]*)\]'", proc.stdout)
    assert found, proc.stdout
    return set(found[-1].split(","))


def test_the_demo_installs_no_test_tools() -> None:
    demo = _pip_extras("setup-demo")
    assert "plots" in demo
    assert not demo & {"dev", "ray", "monitor", "speech", "mcap", "foxglove"}


def test_the_tests_install_every_extra_they_use() -> None:
    assert {"plots", "dev", "speech", "monitor", "ray", "mcap", "foxglove"} <= \
        _pip_extras("setup-test")


def test_stable_baselines3_is_apart_and_gets_torchs_cpu_build_first() -> None:
    """SB3 is not in the tests' set-up (torch is large); ``make sb3`` installs torch's CPU
    build (pinned by its ``+cpu`` local version) before the extra, so the extra cannot pull
    a CUDA build."""
    assert "sb3" not in _pip_extras("setup-test")
    assert "sb3" in _pip_extras("sb3")
    proc = subprocess.run([_make(), "-n", "-B", "-C", str(ROOT), "sb3"], capture_output=True,
                          text=True, check=True)
    lines = proc.stdout.splitlines()
    torch = next(i for i, line in enumerate(lines) if "pip install -q torch==" in line)
    assert re.search(r"torch==[\d.]+\+cpu\b", lines[torch]), lines[torch]
    extra = next(i for i, line in enumerate(lines) if "sb3]'" in line)
    assert torch < extra
    assert sum("sb3_shared_attention.py" in line and "--check" in line for line in lines) == 2


def test_make_sb3_installs_torch_and_sb3_only_not_the_test_tools() -> None:
    """``make sb3`` sets up the demo's environment, then torch and Stable-Baselines3: no test
    tool chain (Ray, Chromium's driver, the monitor) comes with it."""
    proc = subprocess.run([_make(), "-n", "-B", "-C", str(ROOT), "sb3"], capture_output=True,
                          text=True, check=True)
    assert {e for found in re.findall(r"pip install -q -e '\.\[([^\]]*)\]'", proc.stdout)
            for e in found.split(",")} == {"plots", "sb3"}, proc.stdout
    assert "debs-test" not in proc.stdout and "espeak-ng" not in proc.stdout, proc.stdout
