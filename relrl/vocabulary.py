"""Places, head poses, colours and each world's percepts: the project's shared vocabulary.

The definitions live in :mod:`perception.vocabulary`, which imports only the standard library,
so that ``head`` and ``perception`` share them without importing relrl; this module
re-exports them for relrl's users (the same names, its ``__all__``). See
:mod:`perception.vocabulary` for what each name means.
"""

from __future__ import annotations

from perception import vocabulary as _vocabulary
from perception.vocabulary import *  # noqa: F403  (re-exported: the one definition)

__all__ = list(_vocabulary.__all__)
