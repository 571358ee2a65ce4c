"""``relrl tree POLICY``: the learned tree drawn by Graphviz; the tree's text read back."""

from __future__ import annotations

from pathlib import Path

import pytest

from relrl.cli import main
from relrl.monitor.graph import render
from tests.monitor.conftest import FRUITS, episode


def test_a_graph_is_drawn_by_graphviz() -> None:
    g = {"nodes": [{"id": "n0", "kind": "test", "label": "stimulus(face)"},
                   {"id": "n1", "kind": "leaf", "label": "look(centre) 31.0"},
                   {"id": "n2", "kind": "leaf", "label": "look(down) 29.5"}],
         "edges": [{"from": "n0", "to": "n1", "branch": "yes"},
                   {"from": "n0", "to": "n2", "branch": "no"}]}
    svg = render(g).decode()
    assert "<svg" in svg and "stimulus(face)" in svg and "look(centre)" in svg
    assert svg.count('class="node"') == 3 and svg.count('class="edge"') == 2
    assert 'stroke-dasharray' in svg  # the "no" branch is dashed
    assert render(g, "dot").decode().startswith("digraph tree {")


def _policy(tmp_path: Path, learner: str) -> Path:
    script = episode(tmp_path, steps=60, perception="symbolic")
    script.write_text(script.read_text().replace('learner = "etg"', f'learner = "{learner}"'))
    out = tmp_path / learner
    assert main(["run", str(script), "--out", str(out), "--no-plots"]) == 0
    return out / "policy.pl"


@pytest.mark.slow
def test_relrl_tree_draws_an_etg_policy(tmp_path: Path, capsys) -> None:
    policy = _policy(tmp_path, "etg")
    capsys.readouterr()
    svg = tmp_path / "tree.svg"
    assert main(["tree", str(policy), "--domain", str(FRUITS), "--out", str(svg)]) == 0
    said = capsys.readouterr().out
    assert said.startswith(f"wrote {svg}: etg tree of policy.pl: ")
    text = svg.read_text()
    assert text.lstrip().startswith("<?xml") and "<svg" in text
    assert text.count('class="node"') >= 3 and "stimulus(" in text
    png = tmp_path / "tree.png"
    assert main(["tree", str(policy), "--domain", str(FRUITS), "--out", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    capsys.readouterr()
    assert main(["tree", str(policy), "--domain", str(FRUITS)]) == 0
    assert capsys.readouterr().out.startswith("digraph tree {")


@pytest.mark.parametrize("case", ["contingency", "no-domain", "bad-format", "missing"])
@pytest.mark.slow
def test_relrl_tree_errors_are_one_line(tmp_path: Path, capsys, case: str) -> None:
    args = {"contingency": lambda: [str(_policy(tmp_path, "contingency")), "--domain",
                                    str(FRUITS)],
            "no-domain": lambda: [str(_policy(tmp_path, "etg"))],
            "bad-format": lambda: [str(_policy(tmp_path, "etg")), "--domain", str(FRUITS),
                                   "--out", str(tmp_path / "t.gif")],
            "missing": lambda: [str(tmp_path / "nothing.pl"), "--domain", str(FRUITS)]}[case]()
    capsys.readouterr()
    assert main(["tree", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("relrl tree: "), err
    if case == "contingency":
        assert "no tree to draw" in err[0]
