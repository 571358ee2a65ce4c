"""Camera frames to perception facts: saliency, colour, faces and head pose, ART2.

The public surface::

    perceive(frame, *, state=None, looking_at=None) -> list[Fact]   # one call per frame
    Perceiver                      # keeps the face tracker between frames; .analyse() for all
    format_fact(fact) -> str       # ("see", "face") -> "see(face)."
    SceneView, render              # the synthetic camera's scene and renderer
    open_camera(src) -> Camera     # 0, cam://0, video file, folder, synthetic://
    ART2, FruitNamer               # colour categories named by a caregiver (Table 1)
    PLACES, POSES, COLOURS, HUES   # the shared vocabulary

Heavy imports (OpenCV) happen on first use, so importing this package is cheap.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

__all__ = [
    # colour naming
    "ART2",
    "COLOURS",
    "HUES",
    # vocabulary
    "PLACES",
    "POSES",
    "FruitNamer",
    "Perceiver",
    # the synthetic camera and camera sources
    "SceneView",
    "format_fact",
    "open_camera",
    # one call per frame
    "perceive",
    "render",
]

_WHERE = {
    "perceive": "perception.pipeline", "Perceiver": "perception.pipeline",
    "format_fact": "perception.facts", "SceneView": "perception.render",
    "render": "perception.render", "open_camera": "perception.camera",
    "ART2": "perception.art2", "FruitNamer": "perception.art2",
    "PLACES": "perception.vocabulary", "POSES": "perception.vocabulary",
    "COLOURS": "perception.vocabulary", "HUES": "perception.vocabulary",
}


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        module = _WHERE[name]
        loaded = import_module(module)
        # Importing a submodule binds its name on this package (perception.render the
        # module would shadow render the function): bind every name it provides now.
        for other, where in _WHERE.items():
            if where == module:
                globals()[other] = getattr(loaded, other)
        return globals()[name]
    raise AttributeError(f"module 'perception' has no attribute {name!r}")
