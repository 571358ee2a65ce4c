"""The Foxglove layout shipped with relrl: a dashboard for a recorded or live session.

``examples/foxglove/relrl-layout.json`` (:data:`LAYOUT`) is built here with foxglove-sdk's
layout classes (:mod:`foxglove.layouts`): in Foxglove, *Layouts* -> *Import from file*, then
open a recording (or connect to ``--foxglove``) and every panel has its topic:

* a **3D** panel following ``base_link``: the head's robot description from
  ``/robot_description`` moved by ``/tf``, the gaze and the caregiver's face from
  ``/head/scene``;
* an **Image** panel on the camera with its annotations (face box, salient area);
* **Plots** of the running CGI and eye contacts (``/relrl/interaction``) and of the
  necessity units and the reward (``/relrl/necessities``, ``/relrl/reward``; the necessity
  plotted is ``socialize``, the shipped domains': add yours in the panel's settings);
* **Raw Messages** on ``/relrl/tree`` (the learner's tree) and ``/relrl/response`` (the
  choice, the path of tests and the ranked actions).

``python -m relrl.recording.layout`` prints the layout; a test keeps the shipped file equal
to it and its topics among the recording's channels (:func:`topics_of`).
"""

from __future__ import annotations

import json
import sys
from typing import Any

from relrl.resources import examples_dir

__all__ = ["LAYOUT", "build_layout", "layout_json", "topics_of"]

#: the shipped layout file.
LAYOUT = examples_dir() / "foxglove" / "relrl-layout.json"


def build_layout() -> Any:
    """The dashboard as a :class:`foxglove.layouts.Layout`."""
    import foxglove.layouts as fl

    three_d = fl.ThreeDeePanel(title="head", config=fl.ThreeDeeConfig(
        follow_tf="base_link",
        layers={
            "grid": fl.BaseRendererGridLayerSettings(instance_id="grid",
                                                     layer_id="foxglove.Grid"),
            "head": fl.BaseRendererUrdfLayerSettings(
                instance_id="head", layer_id="foxglove.Urdf", label="WHA-8030 head",
                source_type="topic", topic="/robot_description",
                control_mode="transforms", display_mode="visual"),
        },
        topics={"/head/scene": fl.BaseRendererSceneUpdateTopicSettings(visible=True)},
    ))
    image = fl.ImagePanel(title="camera", config=fl.ImageConfig(image_mode=fl.ImageModeConfig(
        image_topic="/camera/image/compressed",
        annotations={"/camera/annotations": fl.ImageAnnotationSettings(visible=True)})))

    def plot(title: str, *paths: tuple[str, str]) -> Any:
        return fl.PlotPanel(title=title, config=fl.PlotConfig(
            paths=[fl.PlotSeries(value=value, label=label, enabled=True)
                   for value, label in paths]))

    def raw(title: str, path: str) -> Any:
        return fl.RawMessagesPanel(title=title, config=fl.RawMessagesConfig(topic_path=path))

    return fl.Layout(content=fl.SplitContainer(direction="column", items=[
        fl.SplitItem(proportion=3, content=fl.SplitContainer(direction="row", items=[
            fl.SplitItem(content=three_d), fl.SplitItem(content=image)])),
        fl.SplitItem(proportion=2, content=fl.SplitContainer(direction="row", items=[
            fl.SplitItem(content=plot("CGI", ("/relrl/interaction.metrics.cgi", "CGI"))),
            fl.SplitItem(content=plot(
                "necessities and reward",
                ("/relrl/necessities.activation.socialize", "socialize"),
                ("/relrl/reward.reward", "reward"))),
            fl.SplitItem(content=raw("tree", "/relrl/tree")),
            fl.SplitItem(content=raw("response", "/relrl/response")),
        ])),
    ]))


def layout_json() -> str:
    """The layout as the shipped file holds it (indented JSON, a final newline)."""
    return json.dumps(json.loads(build_layout().to_json()), indent=2) + "\n"


def _topic(path: str) -> str:
    """The topic of a message path (``/relrl/reward.reward`` -> ``/relrl/reward``)."""
    return path.split(".", 1)[0].split("{", 1)[0].split("[", 1)[0]


def topics_of(layout: dict[str, Any]) -> set[str]:
    """Every topic a layout's panels read: image and annotation topics, 3D topics and
    layers, and the topics of plotted and shown message paths."""
    found: set[str] = set()

    def walk(node: Any) -> None:
        if isinstance(node, dict):
            for key, value in node.items():
                if key in ("imageTopic", "topic") and isinstance(value, str):
                    found.add(value)
                elif key in ("topicPath", "value") and isinstance(value, str):
                    found.add(_topic(value))
                elif key in ("annotations", "topics") and isinstance(value, dict):
                    found.update(value)
                walk(value)
        elif isinstance(node, list):
            for item in node:
                walk(item)

    walk(layout)
    return found


if __name__ == "__main__":
    sys.stdout.write(layout_json())
