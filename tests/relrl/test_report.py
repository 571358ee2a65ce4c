"""``relrl report``: tables rendered from the runs that made them; generated blocks in a
Markdown file re-rendered in place and checked for staleness; the shipped docs' blocks match
the results.json files they cite."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from relrl.cli import main
from relrl.errors import UserError
from relrl.report import load_run, render, stale_blocks, update_file
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def sis_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("report") / "exp1"
    assert main(["-q", "experiment", "sis", "--learners", "etg,tg", "--points", "2",
                 "--eval-runs", "1", "--eval-steps", "50", "--block", "50", "--workers", "1",
                 "--out", str(out)]) == 0
    return out


@pytest.mark.slow
def test_a_run_renders_its_numbers_and_where_they_come_from(sis_run: Path) -> None:
    run = load_run(sis_run)
    text = render(run, "summary", "exp1")
    results = json.loads((sis_run / "results.json").read_text())
    for name, s in results["summary"].items():
        row = next(line for line in text.splitlines() if line.startswith(f"| {name} |"))
        assert f"{s['cgi_final']:.2f}" in row
    assert "`exp1/results.json`" in text
    assert "relrl -q experiment sis" in text          # the command, from the run record
    assert "cores" in text                             # the machine, from timing.json
    short = render(run, "short", "exp1")
    assert "paper (2012)" in short and "3,150" in short


@pytest.mark.slow
def test_blocks_are_rerendered_in_place_and_staleness_is_found(sis_run: Path,
                                                               tmp_path: Path) -> None:
    shutil.copytree(sis_run, tmp_path / "exp1")
    md = tmp_path / "doc.md"
    md.write_text("# Doc\n\nbefore\n<!-- relrl-report exp1 short -->\nold table\n"
                  "<!-- /relrl-report -->\nafter\n", encoding="utf-8")
    assert stale_blocks(md) == [f"{md}:4: exp1 short"]
    assert update_file(md) == 1
    text = md.read_text()
    assert text.startswith("# Doc\n\nbefore\n") and text.endswith("after\n")
    assert "old table" not in text and stale_blocks(md) == [] and update_file(md) == 0
    # a new number in the run makes the block stale again
    results = json.loads((tmp_path / "exp1" / "results.json").read_text())
    first = next(iter(results["summary"]))
    results["summary"][first]["cgi_final"] = 0.123
    (tmp_path / "exp1" / "results.json").write_text(json.dumps(results))
    assert len(stale_blocks(md)) == 1
    assert main(["report", "--check", str(md)]) == 1
    assert main(["report", "--update", str(md)]) == 0
    assert "0.12" in md.read_text() and main(["report", "--check", str(md)]) == 0


def test_a_results_page_holds_every_view(sis_run: Path, tmp_path: Path) -> None:
    """The page's blocks name runs inside its tree (``--root``, else the git work tree or its
    folder): a run elsewhere is refused when the page is written, not when it is updated."""
    shutil.copytree(sis_run, tmp_path / "runs" / "exp1")
    out = tmp_path / "docs" / "results.md"
    assert main(["report", str(tmp_path / "runs" / "exp1"), "--out", str(out)]) == 2
    assert not out.exists()
    assert main(["report", str(tmp_path / "runs" / "exp1"), "--out", str(out),
                 "--root", str(tmp_path)]) == 0
    assert stale_blocks(out, tmp_path) == []
    assert "<!-- relrl-report ../runs/exp1 summary" in out.read_text()
    assert "](../runs/exp1/fig5_cgi.png)" in out.read_text()
    assert main(["report", "--check", str(out), "--root", str(tmp_path)]) == 0


@pytest.mark.parametrize("content, words", [
    (None, ["results.json", "no such file"]),
    ("{not json", ["results.json:1", "not valid JSON"]),
    ("[1, 2]", ["JSON object"]),
    ('{"a": 1}', ["experiment"]),
])
def test_bad_run_folders_are_one_line(tmp_path: Path, content: str | None,
                                      words: list[str]) -> None:
    if content is not None:
        (tmp_path / "results.json").write_text(content)
    with pytest.raises(UserError) as err:
        load_run(tmp_path)
    assert all(w in str(err.value) for w in words) and "\n" not in str(err.value)


def test_an_unknown_view_names_the_known_ones(sis_run: Path) -> None:
    with pytest.raises(UserError, match="summary"):
        render(load_run(sis_run), "nope")


@pytest.mark.slow
def test_shipped_docs_match_the_runs_they_cite() -> None:
    docs = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    stale = [line for md in docs for line in stale_blocks(md)]
    assert stale == [], "re-render with `relrl report --update FILE.md`:\n" + "\n".join(stale)


def test_the_claims_of_two_runs_side_by_side(sis_run: Path, tmp_path: Path) -> None:
    """A block may name two runs (``a,b``): the paper's claims judged on each, one column per
    setting, and both runs' provenance."""
    for name, preset in (("fixed", None), ("paper", "paper-2012")):
        shutil.copytree(sis_run, tmp_path / name)
        results = json.loads((tmp_path / name / "results.json").read_text())
        results["config"]["preset"] = preset
        results["claims"] = {"after_first_run": {"held": preset is None, "values": {
            "cgi_after_first_run": {"contingency": 0.5, "etg": 0.75, "qlearning": 0.8}}}}
        (tmp_path / name / "results.json").write_text(json.dumps(results))
    md = tmp_path / "doc.md"
    md.write_text("<!-- relrl-report fixed,paper claims -->\n<!-- /relrl-report -->\n")
    assert update_file(md) == 1
    text = md.read_text()
    assert "| the paper's claim | `fixed task` | `paper-2012` |" in text
    assert "**held**: run 1 C 0.50, ETG 0.75, Q 0.80 | not held: run 1 C 0.50" in text
    assert "`fixed/results.json`" in text and "`paper/results.json`" in text
    assert stale_blocks(md) == []


def test_the_provenance_line_never_joins_the_table_above_it(sis_run: Path,
                                                            monkeypatch: pytest.MonkeyPatch
                                                            ) -> None:
    """A view whose Markdown does not end in a newline still gets its provenance as a
    paragraph of its own (else Markdown reads it as one more row of the table)."""
    from relrl import report

    monkeypatch.setitem(report.VIEWS, ("sis", "bare"), lambda run: "| a |\n|---|\n| 1 |")
    assert "| 1 |\n\n*From `exp1/results.json`" in render(load_run(sis_run), "bare", "exp1")


def test_a_symbolic_experiment2_run_has_no_table1_and_says_so(tmp_path: Path) -> None:
    """Experiment 2 with symbolic perception names no fruit (no Table 1): the short view
    shows a dash, the Table 1 view is a one-line error, not a traceback."""
    summary = {"tg/interaction": {
        "fig6": [{"units": 0, "cgi_mean": 0.5, "cgi_sd_over_seeds": 0.1},
                 {"units": 100, "cgi_mean": 1.0, "cgi_sd_over_seeds": 0.0}],
        "table1": {"all_executions": None, "executions": 25, "without_presentation": 25}}}
    (tmp_path / "results.json").write_text(json.dumps({"experiment": "exp2",
                                                       "summary": summary}))
    short = render(load_run(tmp_path), "short", "exp2")
    assert "| tg/interaction | 1.00 | — |" in short
    with pytest.raises(UserError, match="no Table 1"):
        render(load_run(tmp_path), "table1", "exp2")


def test_experiment2_views_of_a_run_with_table1_for_one_reading_only(tmp_path: Path) -> None:
    """Table 1 is run for one reading of the time unit: its view shows that reading's
    columns; the confusions view ranks what the robot would have said, in % of the fruit."""
    t1 = {"all_executions": {"success": [80.0, 3.0], "unknown": [6.0, 1.0]}}
    summary = {"etg/interaction": {"fig6": [], "table1": t1,
                                   "confusion": {"apple": {"apple": 9, "nothing": 1}}},
               "etg/step": {"fig6": [], "table1": None}}
    (tmp_path / "results.json").write_text(json.dumps({"experiment": "exp2",
                                                       "summary": summary}))
    table1 = render(load_run(tmp_path), "table1", "exp2")
    assert "| measure (%) | paper | etg/interaction |" in table1
    assert "| success | — | 80.00 ± 3.00 |" in table1
    confusions = render(load_run(tmp_path), "confusions", "exp2")
    assert "| etg/interaction | apple | apple 90.0 %, nothing 10.0 % |" in confusions


def test_the_summary_counts_the_evaluation_points_the_demo_counts(sis_run: Path) -> None:
    """``--points 2`` evaluates three times (before learning, after each block): the summary
    says 3, as ``relrl demo`` does of its own run and as the curve holds."""
    text = render(load_run(sis_run), "summary", "exp1")
    curve = next(iter(json.loads((sis_run / "results.json").read_text())["summary"].values()))
    assert len(curve["curve"]) == 3
    assert "3 evaluation points (the first before learning)" in text, text


def test_a_machine_path_in_the_command_is_not_shown(sis_run: Path, tmp_path: Path) -> None:
    """A run written into an absolute folder (``--out /home/me/runs/x``) is shown as made by
    ``--out DIR``: no machine's path reaches a document."""
    run = tmp_path / "abs"
    shutil.copytree(sis_run, run)
    record = json.loads((run / ".relrl-run.json").read_text())
    record["command"] = "relrl experiment sis --workers 2 --out /home/me/scratch/exp1"
    (run / ".relrl-run.json").write_text(json.dumps(record))
    text = render(load_run(run), "short", "abs")
    assert "made by `relrl experiment sis --workers 2 --out DIR`" in text, text
    assert "/home/me" not in text
