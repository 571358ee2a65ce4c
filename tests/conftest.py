"""Shared fixtures: paths of the example domains and a factory for small domain files; the
``sb3`` selection."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FRUITS = ROOT / "examples" / "domains" / "fruits.pl"
SIS = ROOT / "examples" / "domains" / "sis.pl"


@pytest.fixture
def write_domain(tmp_path: Path):
    """Write a domain file from text and return its path."""
    def write(text: str, name: str = "domain.pl") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path
    return write


def default_signals() -> None:
    """For ``subprocess.Popen(preexec_fn=...)``: the child starts with SIGINT and SIGTERM at
    their defaults and unblocked, as from a user's shell, whatever this test process (with
    SWI-Prolog, Ray and browser drivers loaded in it) has done to its own dispositions."""
    import signal

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Tests marked ``sb3`` need Stable-Baselines3 and torch, which only ``make test-sb3``
    installs (and then runs them, ``pytest -m sb3``). They run when the ``-m`` expression
    names ``sb3``; otherwise they are deselected (counted as deselected; neither run nor
    skipped), so ``make test`` and ``make check`` do not need PyTorch."""
    if "sb3" in (config.getoption("markexpr") or ""):
        return
    kept = [item for item in items if item.get_closest_marker("sb3") is None]
    if len(kept) < len(items):
        config.hook.pytest_deselected(items=[i for i in items if i not in kept])
        items[:] = kept
