"""Shared fixtures: paths of the example domains and a factory for small domain files."""

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


