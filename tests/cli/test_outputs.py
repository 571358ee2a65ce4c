"""Where commands write: --out refuses another run's folder unless --overwrite, a fresh
timestamped folder by default, files 0644, output files checked before the work, nothing
written outside --out, no stray temporary files."""

from __future__ import annotations

import io
import json
import os
import stat
import sys
import threading
from pathlib import Path

import pytest

from relrl.cli import main
from tests.cli.conftest import episode_text, one_line_exit_2
from tests.cli.test_corpus import BENCH, EXP


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


@pytest.fixture
def umask_022():
    old = os.umask(0o022)
    yield
    os.umask(old)


def test_run_refuses_the_folder_of_another_run_unless_overwrite(capsys, tmp_path):
    script = tmp_path / "e.toml"
    script.write_text(episode_text())
    out = tmp_path / "out"
    assert main(["run", str(script), "--out", str(out), "--no-plots"]) == 0
    record = json.loads((out / ".relrl-run.json").read_text())
    assert record["status"] == "complete" and "summary.json" in record["files"]
    capsys.readouterr()
    one_line_exit_2(capsys, ["run", str(script), "--out", str(out)],
                    str(out), "not empty", f"relrl run {script}", "--overwrite")
    # as if the earlier run had also drawn a plot this one does not draw; a note is added
    record["files"].append("stale.png")
    (out / ".relrl-run.json").write_text(json.dumps(record))
    (out / "stale.png").write_bytes(b"an earlier run's plot")
    (out / "notes.txt").write_text("mine\n")
    assert main(["run", str(script), "--out", str(out), "--no-plots", "--overwrite"]) == 0
    assert (out / "notes.txt").read_text() == "mine\n"
    assert not (out / "stale.png").exists()
    record = json.loads((out / ".relrl-run.json").read_text())
    assert record["kept"] == ["notes.txt"] and "notes.txt" not in record["files"]


def test_overwrite_after_a_run_killed_before_its_record_was_finished(tmp_path):
    script = tmp_path / "e.toml"
    script.write_text(episode_text())
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    (out / ".relrl-run.json").write_text(json.dumps(
        {"command": "relrl run x.toml", "started": "2025-01-01T00:00:00", "ended": None,
         "status": "running", "files": [], "kept": ["notes.txt"]}))
    (out / "trace.jsonl").write_text("{}\n")
    (out / "policy-old.pl").write_text("% half a run\n")
    assert main(["run", str(script), "--out", str(out), "--no-plots", "--overwrite"]) == 0
    assert (out / "notes.txt").exists() and not (out / "policy-old.pl").exists()


def test_a_folder_of_other_files_is_refused_and_never_emptied(capsys, tmp_path):
    out = tmp_path / "papers"
    out.mkdir()
    (out / "draft.tex").write_text("\\documentclass{article}\n")
    script = tmp_path / "e.toml"
    script.write_text(episode_text())
    one_line_exit_2(capsys, ["run", str(script), "--out", str(out)], "1 files", "--overwrite")
    assert main(["run", str(script), "--out", str(out), "--overwrite", "--no-plots"]) == 0
    assert (out / "draft.tex").exists() and (out / "summary.json").exists()


def _quick_sis(config, out, workers=1, **engine):
    """Stands in for Experiment 1 (the folder policy is under test, not the experiment)."""
    from relrl.experiments.report import write_json_atomic

    out = Path(out)
    write_json_atomic(out / "results.json", {"seeds": config.seeds})
    (out / "fig5_cgi.csv").write_text("learner,point\n")
    return {"summary": {}}, [out / "results.json", out / "fig5_cgi.csv"]


def test_experiment_writes_a_fresh_timestamped_folder_by_default(capsys, tmp_path,
                                                                 monkeypatch, umask_022):
    monkeypatch.setattr("relrl.experiments.main.run_sis", _quick_sis)
    monkeypatch.chdir(tmp_path)
    assert main(EXP) == 0
    assert main(EXP) == 0
    folders = sorted((tmp_path / "runs").iterdir())
    assert len(folders) == 2 and all(f.name.startswith("exp1-") for f in folders)
    for folder in folders:
        for name in ("results.json", "fig5_cgi.csv", ".relrl-run.json"):
            assert _mode(folder / name) == 0o644, name
        assert json.loads((folder / ".relrl-run.json").read_text())["status"] == "complete"
    out = capsys.readouterr().out
    assert all(f"files to {f.relative_to(tmp_path)}/:" in out for f in folders)


def test_run_outputs_are_0644_and_the_policy_may_go_in_a_subfolder(tmp_path, umask_022):
    script = tmp_path / "e.toml"
    script.write_text(episode_text(head='policy_save = "policies/etg/p.pl"'))
    out = tmp_path / "out"
    assert main(["run", str(script), "--out", str(out)]) == 0
    for name in ("summary.json", "timing.json", "trace.jsonl", "policies/etg/p.pl",
                 ".relrl-run.json", "rewards.png"):
        assert _mode(out / name) == 0o644, name
    assert json.loads((out / "summary.json").read_text())["policy"] == "policies/etg/p.pl"


def test_a_policy_folder_that_leads_outside_out_is_not_followed(tmp_path, capsys):
    script = tmp_path / "e.toml"
    script.write_text(episode_text(head='policy_save = "link/p.pl"'))
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "link").symlink_to(elsewhere)
    assert main(["run", str(script), "--out", str(out), "--overwrite", "--no-plots"]) == 0
    assert not (elsewhere / "p.pl").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert "policy" not in summary and "leads outside" in summary["policy_error"]
    assert "the policy was not saved" in capsys.readouterr().err


def test_bench_json_into_a_folder_leaves_no_stray_file(capsys, tmp_path):
    (tmp_path / "adir").mkdir()
    before = set(tmp_path.rglob("*"))
    one_line_exit_2(capsys, BENCH + ["--json", str(tmp_path / "adir")], "adir", "folder")
    assert set(tmp_path.rglob("*")) == before


def test_bench_json_creates_its_folder_and_writes_to_a_pipe(capsys, tmp_path, umask_022,
                                                           monkeypatch):
    monkeypatch.setattr("relrl.bench.bench_all", lambda **kw: {"gateway_call_us": 30.0})
    path = tmp_path / "new" / "b.json"
    assert main(BENCH + ["--json", str(path)]) == 0
    assert "gateway_call_us" in json.loads(path.read_text()) and _mode(path) == 0o644
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    assert main(BENCH + ["--json", str(fifo)]) == 0
    reader.join(timeout=30)
    assert stat.S_ISFIFO(fifo.stat().st_mode) and b'"gateway_call_us"' in got[0]


def test_perceive_annotate_creates_its_folder(tmp_path, umask_022):
    path = tmp_path / "new" / "seen.jpg"
    assert main(["perceive", "--camera", "synthetic://?size=64x48", "--annotate",
                 str(path)]) == 0
    assert path.read_bytes()[:2] == b"\xff\xd8" and _mode(path) == 0o644


def test_head_calibrate_creates_its_folder(tmp_path, monkeypatch, umask_022):
    path = tmp_path / "new" / "head.toml"
    monkeypatch.setattr(sys, "stdin", io.StringIO("+ x w"))
    assert main(["head", "calibrate", "-o", str(path)]) == 0
    assert "[servos." in path.read_text() and _mode(path) == 0o644


def test_a_q_table_is_written_0644_too(tmp_path, umask_022):
    script = tmp_path / "q.toml"
    script.write_text(episode_text(head='learner = "qlearning"\npolicy_save = "q.npz"'))
    out = tmp_path / "out"
    assert main(["run", str(script), "--out", str(out), "--no-plots"]) == 0
    assert _mode(out / "q.npz") == 0o644 and list(out.glob(".*.tmp")) == []
