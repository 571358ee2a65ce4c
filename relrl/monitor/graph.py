"""The learned tree as a picture: ``{"nodes", "edges"}`` to Graphviz (DOT, SVG, PNG).

A tree learner (ETG, tg) gives its tree as ``learner.graph()``: nodes ``{"id", "kind"
("test" | "leaf"), "label"}`` and edges ``{"from", "to", "branch" ("yes" | "no")}``.
:func:`to_dot` draws it (tests as boxes, leaves as rounded boxes with their ranked actions,
``yes`` edges solid, ``no`` edges dashed) and :func:`render` runs Graphviz's ``dot`` (Debian
package ``graphviz``, Python package ``graphviz`` from the ``monitor`` extra).
"""

from __future__ import annotations

from typing import Any

from relrl.errors import UserError

__all__ = ["GraphError", "learner_graph", "render", "to_dot"]

#: the longest label line drawn; longer lines are cut with an ellipsis.
LABEL_WIDTH = 48
#: leaf entries shown per leaf (the best first).
LEAF_ENTRIES = 4


class GraphError(UserError):
    """The tree cannot be drawn (Graphviz missing, or a learner without a tree)."""


def learner_graph(learner: Any) -> dict[str, Any] | None:
    """The learner's tree as ``{"nodes", "edges"}``, or ``None`` for learners without one."""
    graph = learner.graph()
    return graph if graph.get("nodes") else None


def shown_graph(learner: Any, previous: dict[str, Any] | None) -> dict[str, Any] | None:
    """:func:`learner_graph` for the monitor: when the query runs out of time (a machine
    too busy to answer within the gateway's limit) the robot goes on and the page keeps the
    tree it has (``previous``); the miss is logged."""
    import logging

    from relrl.errors import QueryTimeout

    try:
        return learner_graph(learner)
    except QueryTimeout as exc:
        logging.getLogger(__name__).warning("the tree was not redrawn: %s", exc)
        return previous


def _cut(text: str) -> str:
    lines = str(text).splitlines() or [""]
    return "\n".join(s if len(s) <= LABEL_WIDTH else s[:LABEL_WIDTH - 1] + "…" for s in lines)


def to_dot(graph: dict[str, Any], title: str = "") -> Any:
    """A ``graphviz.Digraph`` of the tree.

    Raises:
        GraphError: the Python package ``graphviz`` is not installed.
    """
    try:
        import graphviz
    except ImportError:
        raise GraphError("drawing the tree needs the optional extra: pip install "
                         "'relrl[monitor]' (the graphviz package)") from None
    dot = graphviz.Digraph("tree", graph_attr={"rankdir": "TB", "fontsize": "10",
                                               "label": title, "labelloc": "t"},
                           node_attr={"fontname": "Helvetica", "fontsize": "9"},
                           edge_attr={"fontname": "Helvetica", "fontsize": "8"})
    styles = {"test": {"shape": "box", "style": "filled", "fillcolor": "#dbe9f6"},
              "leaf": {"shape": "box", "style": "rounded,filled", "fillcolor": "#e6f4e1"},
              "null": {"shape": "plaintext", "fontcolor": "#888888"}}
    for node in graph.get("nodes", []):
        dot.node(str(node["id"]), _cut(node.get("label", "")),
                 **styles.get(node.get("kind", "leaf"), styles["leaf"]))
    for edge in graph.get("edges", []):
        branch = edge.get("branch", "")
        dot.edge(str(edge["from"]), str(edge["to"]), label=str(branch),
                 style="dashed" if branch == "no" else "solid")
    return dot


def render(graph: dict[str, Any], fmt: str = "svg", title: str = "") -> bytes:
    """The tree drawn by Graphviz's ``dot`` in ``fmt`` (svg, png, pdf, dot).

    Raises:
        GraphError: Graphviz (the ``dot`` program) is missing, or ``fmt`` is unknown.
    """
    dot = to_dot(graph, title)
    if fmt == "dot":
        return dot.source.encode()
    import graphviz

    try:
        return dot.pipe(format=fmt)
    except graphviz.ExecutableNotFound:
        raise GraphError("Graphviz's dot program is missing; install the Debian package "
                         "graphviz") from None
    except ValueError as exc:
        raise GraphError(f"cannot draw the tree as {fmt!r}: {exc}") from None
