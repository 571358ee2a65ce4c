"""Places, head poses, colours and each world's percepts: the project's shared vocabulary.

The definitions live in :mod:`perception.vocabulary`, which imports only the standard library,
so that ``head`` and ``perception`` share them without importing relrl; this module
re-exports them for relrl's users. See :mod:`perception.vocabulary` for what each name means.
"""

from __future__ import annotations

from perception.vocabulary import (
    ANY,
    COLOURS,
    FRUIT_COLOURS,
    GAZE_POSE,
    OBJECT_PLACES,
    PLACES,
    POSES,
    SIS_POSES,
    WORLDS,
    Vocabulary,
    episodes_vocabulary,
    sis_vocabulary,
    world,
)

__all__ = [
    "ANY",
    "COLOURS",
    "FRUIT_COLOURS",
    "GAZE_POSE",
    "OBJECT_PLACES",
    "PLACES",
    "POSES",
    "SIS_POSES",
    "WORLDS",
    "Vocabulary",
    "episodes_vocabulary",
    "sis_vocabulary",
    "world",
]
