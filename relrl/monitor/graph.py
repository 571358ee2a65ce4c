"""The learned tree as a picture: ``{"nodes", "edges"}`` to Graphviz (DOT, SVG, PNG).

A tree learner (ETG, tg) gives its tree as ``learner.graph()``: nodes ``{"id", "kind"
("test" | "leaf"), "label"}`` and edges ``{"from", "to", "branch" ("yes" | "no")}``.
:func:`to_dot` draws it (tests as boxes, leaves as rounded boxes with their ranked actions,
``yes`` edges solid, ``no`` edges dashed) and :func:`render` runs Graphviz's ``dot`` (Debian
package ``graphviz``, Python package ``graphviz`` from the ``monitor`` extra).

Every text that reaches ``dot`` is data, never markup: labels are cut to a bounded size,
control characters and unpaired surrogates are replaced, backslashes and ``<...>`` lose their
DOT meaning (no HTML-like labels, so no links in the picture), and node names are generated
(``n0``, ``n1``, ...), never taken from the graph. What ``dot`` still refuses is a
:class:`GraphError`.

For the monitor, :func:`picture` gives the SVG with what the page needs to mark a leaf and
its path in it: the name each node got (:func:`node_names`) and each node's parent, and
:data:`LEAF_LEGENDS` says what a learner's leaf labels mean.
"""

from __future__ import annotations

import re
import subprocess
from dataclasses import dataclass, field
from typing import Any

from relrl.errors import UserError

__all__ = ["EMPTY_LEAF", "LEAF_LEGENDS", "GraphError", "Picture", "learner_graph",
           "node_names", "picture", "render", "to_dot"]

#: the longest label line drawn; longer lines are cut with an ellipsis.
LABEL_WIDTH = 48
#: the most lines of one label drawn; more are summarised in a last line.
LABEL_LINES = 12
#: leaf entries shown per leaf (the best first).
LEAF_ENTRIES = 4
#: control characters (but the line break) and unpaired surrogates: replaced in labels.
_UNPRINTABLE = re.compile("[\x00-\x09\x0b-\x1f\x7f\ud800-\udfff]")
#: the label of a leaf that holds nothing yet (a new tree is one such leaf).
EMPTY_LEAF = "(empty leaf: nothing learned here yet)"
#: what the labels of each learner's tree say (the page's legend under the tree). The
#: labels are the learners' own, made in Prolog (qtree.pl for etg, tg_knowledge.pl for tg);
#: tests/monitor check that real trees read as described here.
LEAF_LEGENDS: dict[str, list[dict[str, str]]] = {
    "etg": [
        {"example": "look(left) 29.45 [socialize]",
         "says": "an entry of the leaf: a response, its Q, and in brackets the necessity "
                 "that was active when it was learned ([none]: no necessity was active); "
                 "the best Q first"},
        {"example": "stimulus(face)",
         "says": "a test of the state: yes (solid) when it holds, no (dashed) when not"},
        {"example": "null",
         "says": "a branch no state has reached yet"},
    ],
    "tg": [
        {"example": "Q=29.45 (n=12)",
         "says": "a leaf: the Q of the (state, response) pairs that reach it, and n, how "
                 "many examples it has learned from"},
        {"example": "at(T, P), look(P)",
         "says": "a first-order test over the state and the response, with variables "
                 "(T a toy, P a place): yes (solid) when some binding makes it true"},
    ],
}


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


def node_names(graph: dict[str, Any]) -> dict[str, str]:
    """The name each node gets in the picture, by its id (as text): ``n0``, ``n1``, ... in
    the order of the nodes; an id given twice keeps its first name."""
    names: dict[str, str] = {}
    for node in graph.get("nodes") or ():
        names.setdefault(str(node["id"]), f"n{len(names)}")
    return names


@dataclass(frozen=True)
class Picture:
    """A tree drawn for the monitor.

    Attributes:
        svg: the picture (SVG).
        names: node id (as text) -> the node's name in the picture (its ``<title>``).
        parents: a node's name -> its parent's name (the root has none).
    """

    svg: bytes
    names: dict[str, str] = field(default_factory=dict)
    parents: dict[str, str] = field(default_factory=dict)


def picture(graph: dict[str, Any]) -> Picture:
    """The tree as SVG, with the names and parents the page marks a path with.

    Raises:
        GraphError: as :func:`render`.
    """
    names = node_names(graph)
    parents: dict[str, str] = {}
    for edge in graph.get("edges") or ():
        tail, head = names.get(str(edge["from"])), names.get(str(edge["to"]))
        if tail is not None and head is not None:
            parents.setdefault(head, tail)
    return Picture(render(graph), names, parents)


def _cut(text: Any, width: int = LABEL_WIDTH) -> str:
    """``text`` as at most :data:`LABEL_LINES` lines of ``width`` printable characters."""
    lines = _UNPRINTABLE.sub("\ufffd", str(text)).splitlines() or [""]
    if len(lines) > LABEL_LINES:
        lines = lines[:LABEL_LINES - 1] + [f"… {len(lines) - LABEL_LINES + 1} more lines"]
    return "\n".join(s if len(s) <= width else s[:width - 1] + "…" for s in lines)


def _text(text: Any, width: int = LABEL_WIDTH) -> str:
    """A label for ``dot``: cut (:func:`_cut`), backslashes and ``<...>`` taken literally."""
    import graphviz

    return graphviz.escape(_cut(text, width))


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
                                               "label": _text(title, 160), "labelloc": "t"},
                           node_attr={"fontname": "Helvetica", "fontsize": "9"},
                           edge_attr={"fontname": "Helvetica", "fontsize": "8"})
    styles = {"test": {"shape": "box", "style": "filled", "fillcolor": "#dbe9f6"},
              "leaf": {"shape": "box", "style": "rounded,filled", "fillcolor": "#e6f4e1"},
              "null": {"shape": "plaintext", "fontcolor": "#888888"}}
    names = node_names(graph)  # the graph's node ids -> n0, n1, ...: no id reaches dot
    for node in graph.get("nodes") or ():
        name = names[str(node["id"])]
        kind = str(node.get("kind", "leaf"))
        label = node.get("label", "")
        if kind == "leaf" and not str(label).strip():
            label = EMPTY_LEAF
        dot.node(name, _text(label), **styles.get(kind, styles["leaf"]))
    for edge in graph.get("edges") or ():
        tail, head = names.get(str(edge["from"])), names.get(str(edge["to"]))
        if tail is None or head is None:  # an edge to no node is not drawn
            continue
        branch = str(edge.get("branch", ""))
        dot.edge(tail, head, label=_text(branch),
                 style="dashed" if branch == "no" else "solid")
    return dot


def render(graph: dict[str, Any], fmt: str = "svg", title: str = "") -> bytes:
    """The tree drawn by Graphviz's ``dot`` in ``fmt`` (svg, png, pdf, dot).

    Raises:
        GraphError: Graphviz (the ``dot`` program) is missing, ``fmt`` is unknown, or
            ``dot`` refused the graph (its first error line is said).
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
    except subprocess.CalledProcessError as exc:
        said = (exc.stderr or b"").decode("utf-8", "replace").strip().splitlines()
        raise GraphError("Graphviz's dot refused the tree: "
                         + (said[0] if said else f"exit status {exc.returncode}")) from None
