"""No import cycles in relrl, perception and head: the graph of every import of their modules
(at the top of a module, inside a function, or under ``if TYPE_CHECKING:``) is acyclic, so no
function-local import is there to break a cycle and no cycle hides behind the type checker.

And one way in: above the transport (relrl/bridge), only the facade (relrl/kb.py) reaches
the process's Prolog (``relrl.bridge.calls.prolog``); everything else goes through a
:class:`~relrl.kb.KnowledgeBase` or :func:`relrl.kb.layer_api`."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from tests.conftest import ROOT

PACKAGES = ("relrl", "perception", "head")


def modules() -> dict[str, Path]:
    """Every module of the packages, by dotted name (a package by its ``__init__``)."""
    found = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            found[".".join(parts)] = path
    return found


def _type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or \
        (isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def imported(name: str, path: Path, known: dict[str, Path], *,
             type_checking: bool = True) -> set[str]:
    """The modules of ``known`` that module ``name`` imports anywhere (with
    ``type_checking`` False, not under ``if TYPE_CHECKING:``; ``from P import m`` names
    module ``P.m`` when there is one)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]

    def owner(dotted: str) -> str | None:
        while dotted and dotted not in known:
            dotted = dotted.rpartition(".")[0]
        return dotted or None

    out: set[str] = set()

    def visit(node: ast.AST) -> None:
        if not type_checking and isinstance(node, ast.If) and _type_checking(node.test):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            out.update(filter(None, (owner(alias.name) for alias in node.names)))
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            for alias in node.names:
                full = f"{base}.{alias.name}"
                found = full if full in known else owner(base)
                if found:
                    out.add(found)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(path.read_text(), str(path)))
    out.discard(name)
    return out


def cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` (a list of modules, the first repeated at the end), or None."""
    state: dict[str, int] = {}       # 1: on the current path, 2: done
    path: list[str] = []

    def walk(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            if nxt not in state and (found := walk(nxt)):
                return found
        path.pop()
        state[node] = 2
        return None

    for start in sorted(graph):
        if start not in state and (found := walk(start)):
            return found
    return None


@pytest.mark.slow
def test_no_import_cycles() -> None:
    known = modules()
    graph = {name: imported(name, path, known) for name, path in known.items()}
    assert len(graph) > 100 and graph["relrl.kb"], "the modules were not found"
    found = cycle(graph)
    assert found is None, "import cycle: " + " -> ".join(found)


def test_the_cycle_finder_finds_one() -> None:
    """The check can fail: a cycle through a function-local import is found."""
    assert cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == ["a", "b", "c", "a"]
    assert cycle({"a": {"b"}, "b": set()}) is None


def test_type_checking_imports_count() -> None:
    """An import under ``if TYPE_CHECKING:`` is an edge of the graph: a cycle behind it is
    found."""
    known = modules()
    assert "relrl.kb" in imported("relrl.engine", known["relrl.engine"], known)
    assert "relrl.kb" not in imported("relrl.engine", known["relrl.engine"], known,
                                      type_checking=False)


def reaches_the_transport(path: Path) -> bool:
    """True when the module at ``path`` imports ``prolog`` from relrl.bridge.calls or
    calls ``relrl.bridge.calls.prolog`` by its dotted name."""
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and (node.module or "").endswith("bridge.calls") \
                and any(alias.name == "prolog" for alias in node.names):
            return True
        if isinstance(node, ast.Attribute) and node.attr == "prolog" and \
                ast.unparse(node.value).endswith("bridge.calls"):
            return True
    return False


def test_one_way_in() -> None:
    facade = {ROOT / "relrl" / "kb.py"}
    bridge = ROOT / "relrl" / "bridge"
    above = [path for path in modules().values()
             if bridge not in path.parents and path not in facade]
    found = sorted(str(p.relative_to(ROOT)) for p in above if reaches_the_transport(p))
    assert not found, f"modules that reach Prolog past relrl.kb: {found}"
    assert reaches_the_transport(ROOT / "relrl" / "kb.py"), "the check finds no use"
