"""Where commands write: --out refuses another run's folder unless --overwrite, a fresh
timestamped folder by default, one command per folder at a time, files 0644, output files
checked before the work, nothing written outside --out -- no link followed, no file written
in place -- and no stray temporary files."""

from __future__ import annotations

import io
import json
import os
import re
import signal
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from relrl.cli import main
from tests.cli.conftest import FRUITS, ROOT, episode_text, one_line_exit_2
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


def _traced(out: Path, lines: int, proc: subprocess.Popen, timeout: float = 240) -> None:
    """Wait until ``out/trace.jsonl`` has ``lines`` lines (a loaded machine starts Python
    slowly)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            if (out / "trace.jsonl").read_text().count("\n") >= lines:
                return
        except FileNotFoundError:
            pass
        time.sleep(0.05)
    raise AssertionError(f"the run did not trace {lines} lines (exit {proc.poll()})")


def _relrl(*argv: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "relrl", *argv], cwd=ROOT, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


@pytest.mark.slow
def test_overwrite_after_kill_9_keeps_a_file_added_after_the_crash(tmp_path):
    """The killed run's journal names what it wrote: NOTES.txt, added after the crash, and
    draft.tex, there before the run, are kept; the killed run's files are replaced."""
    (tmp_path / "long.toml").write_text(episode_text(steps=100000))
    out = tmp_path / "out"
    out.mkdir()
    (out / "draft.tex").write_text("mine, from before\n")
    proc = _relrl("run", str(tmp_path / "long.toml"), "--out", str(out), "--overwrite",
                  "--no-plots", "--record")
    try:
        _traced(out, 5, proc)
    finally:
        proc.kill()
        proc.communicate(timeout=60)
    assert json.loads((out / ".relrl-run.json").read_text())["status"] == "running"
    (out / "NOTES.txt").write_text("what went wrong\n")
    script = tmp_path / "e.toml"
    script.write_text(episode_text())
    assert main(["run", str(script), "--out", str(out), "--no-plots", "--overwrite"]) == 0
    assert (out / "NOTES.txt").read_text() == "what went wrong\n"
    assert (out / "draft.tex").read_text() == "mine, from before\n"
    for gone in ("trees.jsonl", "events.jsonl", "episode.toml", "domain.pl"):
        assert not (out / gone).exists(), gone  # the killed run's, not written again
    record = json.loads((out / ".relrl-run.json").read_text())
    assert record["status"] == "complete"
    assert record["kept"] == ["NOTES.txt", "draft.tex"]
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == [
        ".relrl-run.json"]


def test_overwrite_deletes_nothing_through_a_link(tmp_path):
    """The journal of a killed run names frames/000001.jpg; frames/ is now a link: the file
    it leads to is not the run's, and stays."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "000001.jpg").write_bytes(b"someone else's")
    out = tmp_path / "out"
    out.mkdir()
    (out / ".relrl-run.json").write_text(json.dumps(
        {"command": "relrl run x.toml", "started": "2025-01-01T00:00:00", "ended": None,
         "status": "running", "files": [], "kept": []}))
    (out / ".relrl-run.files").write_text('"frames/"\n"frames/000001.jpg"\n"trace.jsonl"\n')
    (out / "frames").symlink_to(elsewhere)
    (out / "trace.jsonl").write_text("{}\n")
    script = tmp_path / "e.toml"
    script.write_text(episode_text())
    assert main(["run", str(script), "--out", str(out), "--no-plots", "--overwrite"]) == 0
    assert (elsewhere / "000001.jpg").read_bytes() == b"someone else's"
    assert (out / "trace.jsonl").read_text().count("\n") == 6


def test_a_policy_that_cannot_be_saved_at_the_end_is_not_a_success(capsys, tmp_path):
    """A link planted in the policy's path during the run: the policy is not written through
    it, summary.json says why, and the run ends in one line and exit 2."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    script = tmp_path / "e.toml"
    script.write_text(episode_text(steps=400, head='policy_save = "sub/p.pl"'))
    out = tmp_path / "out"

    def plant() -> None:
        (out / "sub").symlink_to(elsewhere)

    watcher = threading.Thread(target=lambda: (_wait_for(out / "trace.jsonl"), plant()),
                               daemon=True)
    watcher.start()
    code = main(["run", str(script), "--out", str(out), "--no-plots"])
    watcher.join()
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert code == 2 and len(err) == 1 and "the policy was not saved" in err[0], err
    assert "sub is a symbolic link" in err[0]
    assert list(elsewhere.iterdir()) == []
    summary = json.loads((out / "summary.json").read_text())
    assert "policy" not in summary and "symbolic link" in summary["policy_error"]
    assert json.loads((out / ".relrl-run.json").read_text())["status"] == "partial"


def _wait_for(path: Path, timeout: float = 60) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and not path.exists():
        time.sleep(0.005)


@pytest.mark.slow
def test_a_second_command_on_a_folder_in_use_is_refused(capsys, tmp_path):
    """One command per folder: an experiment cannot start in the folder of a running one
    (whose folder holds only its record), nor can --overwrite take it from under it."""
    out = tmp_path / "out"
    first = _relrl("experiment", "sis", "--learners", "etg", "--points", "50",
                   "--eval-runs", "1", "--eval-steps", "10", "--block", "10",
                   "--workers", "1", "--out", str(out))
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline and first.poll() is None \
                and not (out / ".relrl-run.json").exists():
            time.sleep(0.05)
        assert first.poll() is None, first.communicate()
        one_line_exit_2(capsys, EXP + ["--out", str(out)], str(out),
                        "`relrl experiment sis --learners etg --points 50", "is writing into")
        script = tmp_path / "e.toml"
        script.write_text(episode_text())
        one_line_exit_2(capsys, ["run", str(script), "--out", str(out), "--overwrite"],
                        str(out), "is writing into")
        assert not (out / "results.json").exists() and not (out / "trace.jsonl").exists()
    finally:
        first.send_signal(signal.SIGTERM)
        _, err = first.communicate(timeout=120)
    assert first.returncode == 128 + signal.SIGTERM, err
    record = json.loads((out / ".relrl-run.json").read_text())
    assert record["command"].startswith("relrl experiment sis --learners etg --points 50")
    assert record["status"] == "partial"
    results = json.loads((out / "results.json").read_text())
    assert results["partial"] and results["interrupted_by"] == "SIGTERM"


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
    from relrl.experiments.results import write_json_atomic

    out = Path(out)
    write_json_atomic(out / "results.json", {"seeds": config.seeds})
    (out / "fig5_cgi.csv").write_text("learner,point\n")
    return {"summary": {}}, [out / "results.json", out / "fig5_cgi.csv"]


def test_experiment_writes_a_fresh_timestamped_folder_by_default(capsys, tmp_path,
                                                                 monkeypatch, umask_022):
    monkeypatch.setattr("relrl.experiments.sis.run_sis", _quick_sis)
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


@pytest.mark.slow
def test_run_outputs_are_0644_and_the_policy_may_go_in_a_subfolder(tmp_path, umask_022):
    script = tmp_path / "e.toml"
    script.write_text(episode_text(head='policy_save = "policies/etg/p.pl"'))
    out = tmp_path / "out"
    assert main(["run", str(script), "--out", str(out)]) == 0
    for name in ("summary.json", "timing.json", "trace.jsonl", "policies/etg/p.pl",
                 ".relrl-run.json", "rewards.png"):
        assert _mode(out / name) == 0o644, name
    assert json.loads((out / "summary.json").read_text())["policy"] == "policies/etg/p.pl"


def test_a_policy_folder_that_leads_outside_out_is_refused_before_the_run(tmp_path, capsys):
    script = tmp_path / "e.toml"
    script.write_text(episode_text(head='policy_save = "link/p.pl"'))
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "link").symlink_to(elsewhere)
    one_line_exit_2(capsys, ["run", str(script), "--out", str(out), "--overwrite",
                             "--no-plots"], "link", "symbolic link")
    assert list(elsewhere.iterdir()) == [] and not (out / "trace.jsonl").exists()


def test_a_policy_folder_link_is_not_followed_by_run_episode_either(tmp_path):
    """Without a claimed folder (a script calling run_episode) the policy's path is checked
    all the same: the summary says why it was not saved."""
    from relrl.episodes import RunOptions, parse_episode, run_episode

    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / "link").symlink_to(elsewhere)
    ep = parse_episode(episode_text(head='policy_save = "link/p.pl"'), tmp_path / "e.toml")
    summary = run_episode(ep, RunOptions(out=out, plots=False))
    assert list(elsewhere.iterdir()) == [] and "symbolic link" in summary["policy_error"]


# ---- every file through one writer: no link followed, nothing written in place ------------

OUTSIDE = "not relrl's: must never change\n"


def _outside(tmp_path: Path) -> Path:
    path = tmp_path / "outside.txt"
    path.write_text(OUTSIDE)
    return path


@pytest.mark.parametrize("name, flags", [
    ("trace.jsonl", []), ("run.log", []), ("summary.json", []),
    ("episode.toml", ["--record"]), ("session.mcap", ["--record"])])
def test_a_link_kept_under_overwrite_is_refused_not_written_through(capsys, tmp_path, name,
                                                                     flags):
    outside = _outside(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    (out / name).symlink_to(outside)
    script = tmp_path / "e.toml"
    script.write_text(episode_text())
    one_line_exit_2(capsys, ["run", str(script), "--out", str(out), "--overwrite",
                             "--no-plots", *flags], f"{name} is a symbolic link")
    assert outside.read_text() == OUTSIDE and (out / name).is_symlink()


def test_a_hard_link_in_out_is_replaced_never_written_in_place(tmp_path):
    outside = _outside(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    os.link(outside, out / "trace.jsonl")
    script = tmp_path / "e.toml"
    script.write_text(episode_text())
    assert main(["run", str(script), "--out", str(out), "--overwrite", "--no-plots"]) == 0
    assert outside.read_text() == OUTSIDE
    assert (out / "trace.jsonl").read_text().count("\n") == 6


def test_the_recording_process_writes_only_into_the_empty_file_it_was_given(tmp_path):
    """The session makes session.mcap empty through the writer; the recording's own process
    then writes only into an empty regular file: a link put at the name in between, or a
    file with something in it, is refused and left as it was."""
    from relrl.errors import OutputError
    from relrl.recording.mcapfile import _open_new

    outside = _outside(tmp_path)
    link = tmp_path / "linked.mcap"
    link.symlink_to(outside)
    with pytest.raises(OutputError, match="link"):
        _open_new(link)
    full = tmp_path / "full.mcap"
    full.write_text("an earlier session")
    with pytest.raises(OutputError, match="already there"):
        _open_new(full)
    assert outside.read_text() == OUTSIDE and full.read_text() == "an earlier session"
    empty = tmp_path / "empty.mcap"
    empty.touch()
    with _open_new(empty) as fh:
        fh.write(b"x")
    assert empty.read_bytes() == b"x"


def test_an_experiment_output_that_is_a_link_is_refused_before_the_work(capsys, tmp_path):
    outside = _outside(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    (out / "fig5_cgi.csv").symlink_to(outside)
    one_line_exit_2(capsys, EXP + ["--out", str(out), "--overwrite"],
                    "fig5_cgi.csv is a symbolic link")
    assert outside.read_text() == OUTSIDE and not (out / "results.json").exists()


def test_a_folder_link_planted_during_the_run_is_not_followed(capsys, tmp_path, monkeypatch):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()

    def planting_sis(config, out, workers=1, **engine):
        from relrl.experiments.results import write_json_atomic

        (Path(out) / "sub").symlink_to(elsewhere)  # after the claim checked the folder
        write_json_atomic(Path(out) / "sub" / "results.json", {"seeds": config.seeds})
        return {"summary": {}}, []

    monkeypatch.setattr("relrl.experiments.sis.run_sis", planting_sis)
    out = tmp_path / "out"
    one_line_exit_2(capsys, EXP + ["--out", str(out)], "sub is a symbolic link")
    assert list(elsewhere.iterdir()) == []
    assert json.loads((out / ".relrl-run.json").read_text())["status"] == "partial"


def test_tree_out_never_writes_through_a_fixed_temporary_name(tmp_path, corpus):
    outside = _outside(tmp_path)
    out = tmp_path / "t.svg"
    (tmp_path / "t.svg.tmp").symlink_to(outside)
    assert main(["tree", str(corpus / "tree-run" / "policy.pl"), "--domain", str(FRUITS),
                 "--out", str(out)]) == 0
    assert outside.read_text() == OUTSIDE
    assert not out.is_symlink() and out.read_text().lstrip().startswith("<?xml")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["outside.txt", "t.svg", "t.svg.tmp"]


#: calls that write a file, outside relrl.outdir (the one writer).
_WRITES = re.compile(r"open\([^)]*['\"][wax]b?\+?['\"]|\.write_text\(|\.write_bytes\(|"
                     r"savefig\((?!buf)|shutil\.copy|os\.replace\(|os\.rename\(|mkstemp\(|"
                     r"FileHandler\(|np\.savez?\((?!buf)")
#: the writes left alone, and why.
_ELSEWHERE = {
    "relrl/speech.py": "the recogniser's grammar, in a private temporary folder",
    "relrl/monitor/live.py": "the monitor process's OOM score (/proc/self/oom_score_adj)",
    "relrl/shell.py": "clauses typed after [user]., in a private temporary folder",
    "relrl/recording/mcapfile.py": "the recording's process fills the empty session.mcap the "
                                   "writer made (or a new file; never a link, never a file "
                                   "with something in it)",
}


def test_every_file_relrl_writes_goes_through_the_one_writer():
    found = []
    for path in sorted((ROOT / "relrl").rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        if rel.startswith("relrl/outdir/") or rel in _ELSEWHERE:
            continue
        for n, line in enumerate(path.read_text().splitlines(), 1):
            if _WRITES.search(line):
                found.append(f"{rel}:{n}: {line.strip()}")
    assert found == [], "\n".join(found)


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
