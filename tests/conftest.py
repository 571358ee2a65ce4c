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



@pytest.fixture(params=["kernel", "ctypes"])
def crossing(request: pytest.FixtureRequest):
    """Run a test twice: with the gateway's compiled calls (the control step,
    relrl._step_kernel, and the term reader, relrl._read_kernel) and through ctypes alone
    (as without numba). Yields the name of the crossing."""
    from relrl.kb import _get_engine

    engine = _get_engine()
    kernel = engine._load_kernel()
    flatten = engine._flatten
    assert kernel and flatten, "numba is a dependency: the compiled calls must load"
    on = request.param == "kernel"
    engine._kernel, engine._flatten = (kernel, flatten) if on else (False, False)
    try:
        yield request.param
    finally:
        engine._kernel, engine._flatten = kernel, flatten
