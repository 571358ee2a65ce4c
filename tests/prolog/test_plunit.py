"""Run the knowledge layer's plunit tests in plain SWI-Prolog (no Python in the loop)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PLT = sorted((ROOT / "tests" / "prolog").glob("*.plt"))


@pytest.mark.parametrize("plt", PLT, ids=[p.stem for p in PLT])
@pytest.mark.slow
def test_plunit(plt: Path) -> None:
    assert shutil.which("swipl"), "swipl must be installed (make test installs it)"
    proc = subprocess.run(
        ["swipl", "--on-warning=status", "-g", f"consult('{plt}')", "-g", "run_tests",
         "-t", "halt", str(ROOT / "prolog" / "relrl.pl")],
        capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "All " in proc.stderr and "tests passed" in proc.stderr, proc.stderr


@pytest.mark.slow
def test_prolog_layer_loads_without_warnings() -> None:
    """The knowledge layer and both example domains load in plain swipl, warning-free."""
    proc = subprocess.run(
        ["swipl", "--on-warning=status", "--on-error=status", "-g", "halt",
         str(ROOT / "prolog" / "relrl.pl"), str(ROOT / "prolog" / "gateway.pl"),
         str(ROOT / "examples" / "domains" / "fruits.pl")],
        capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
