"""``relrl tree POLICY``: the learned tree drawn by Graphviz; the tree's text read back."""

from __future__ import annotations

from pathlib import Path

import pytest

from relrl.cli import main
from relrl.monitor.graph import parse_tree_text, render
from tests.monitor.conftest import FRUITS, episode

TEXT = """[0] stimulus(face) ?
    yes: [1] fact(frontal(face)) ?
        yes: leaf [3] state 129
              look(centre)  Q=31.0000  [socialize]
              look(left)  Q=29.2000  [socialize]
        no:  null
    no:  leaf [2] state 8
          look(down)  Q=29.5000  [socialize]
"""


def test_the_tree_text_reads_back_as_a_graph() -> None:
    g = parse_tree_text(TEXT)
    kinds = {n["id"]: n["kind"] for n in g["nodes"]}
    assert kinds == {"0": "test", "1": "test", "3": "leaf", "null1": "null", "2": "leaf"}
    assert {(e["from"], e["to"], e["branch"]) for e in g["edges"]} == {
        ("0", "1", "yes"), ("1", "3", "yes"), ("1", "null1", "no"), ("0", "2", "no")}
    leaf = next(n for n in g["nodes"] if n["id"] == "3")
    assert leaf["label"].splitlines()[1].startswith("look(centre)")
    svg = render(g).decode()
    assert "<svg" in svg and "frontal(face)" in svg and "look(centre)" in svg


def _policy(tmp_path: Path, learner: str) -> Path:
    script = episode(tmp_path, steps=60, perception="symbolic")
    script.write_text(script.read_text().replace('learner = "etg"', f'learner = "{learner}"'))
    out = tmp_path / learner
    assert main(["run", str(script), "--out", str(out), "--no-plots"]) == 0
    return out / "policy.pl"


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
def test_relrl_tree_errors_are_one_line(tmp_path: Path, capsys, case: str) -> None:
    policy = _policy(tmp_path, "contingency") if case == "contingency" else tmp_path / "p.pl"
    args = {"contingency": [str(policy), "--domain", str(FRUITS)],
            "no-domain": [str(_policy(tmp_path, "etg"))],
            "bad-format": [str(_policy(tmp_path, "etg")), "--domain", str(FRUITS),
                           "--out", str(tmp_path / "t.gif")],
            "missing": [str(tmp_path / "nothing.pl"), "--domain", str(FRUITS)]}[case]
    capsys.readouterr()
    assert main(["tree", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("relrl tree: "), err
    if case == "contingency":
        assert "no tree to draw" in err[0]
