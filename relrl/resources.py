"""Files relrl ships: the knowledge layer (``prolog/``) and the examples (``examples/``).

Both are package data of the ``relrl`` package and are found through
:mod:`importlib.resources`, so they are there whether relrl was installed from a wheel
(``pip install .``), in editable mode (``pip install -e .``) or run from a checkout. In the
source tree ``relrl/prolog`` and ``relrl/examples`` are links to the top-level ``prolog/`` and
``examples/`` folders, which stay where a Prolog user expects them
(``swipl prolog/relrl.pl examples/domains/fruits.pl``); a wheel holds copies.

``RELRL_PROLOG_DIR`` points relrl at another copy of the knowledge layer (a development
checkout, say) without reinstalling.
"""

from __future__ import annotations

import os
from importlib.resources import files
from pathlib import Path

from relrl.errors import RelrlError

__all__ = ["example", "examples_dir", "prolog_dir"]


def _package_dir(name: str) -> Path:
    # Prolog consults real files: the package must be installed as folders (pip always
    # installs wheels unpacked), not imported from a zip archive.
    path = Path(str(files("relrl") / name))
    if not path.is_dir():
        raise RelrlError(f"relrl's {name}/ folder is missing from the installed package "
                         f"(looked in {path}); reinstall relrl")
    return path


def prolog_dir() -> Path:
    """The folder of relrl's Prolog files (``relrl.pl``, ``gateway.pl``, ...).

    ``RELRL_PROLOG_DIR`` overrides the installed copy.
    """
    override = os.environ.get("RELRL_PROLOG_DIR")
    return Path(override) if override else _package_dir("prolog")


def examples_dir() -> Path:
    """The folder of the shipped examples: ``domains/``, ``episodes/``, ``heads/``."""
    return _package_dir("examples")


def example(relative: str | os.PathLike) -> Path:
    """A shipped example file, e.g. ``example("domains/sis.pl")``.

    Raises:
        RelrlError: relrl ships no such file.
    """
    path = examples_dir() / relative
    if not path.is_file():
        raise RelrlError(f"relrl ships no example {relative} (looked in {path})")
    return path
