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
