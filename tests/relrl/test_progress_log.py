"""Progress with ETA in logs and terminals; -v/-q; the session's log file."""

from __future__ import annotations

import io
import logging
import time
from pathlib import Path

import pytest

from relrl import log
from relrl.cli import main
from relrl.progress import progress
from tests.monitor.conftest import episode


def test_progress_without_a_terminal_logs_lines_with_eta(monkeypatch) -> None:
    err = io.StringIO()  # not a terminal: a log
    monkeypatch.setattr("sys.stderr", err)
    log.setup(0)
    bar = progress(10, "learning", unit="unit", interval=0.0)
    for _ in range(4):
        bar.update(1)
    bar.close()
    lines = err.getvalue().splitlines()
    assert len(lines) == 4
    assert lines[-1].startswith("relrl: learning:  40%") and "4/10" in lines[-1]
    assert "<" in lines[-1] and "unit/s" in lines[-1]  # elapsed<remaining (the ETA), rate


def test_progress_on_a_terminal_is_a_tqdm_bar(monkeypatch) -> None:
    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    tty = Tty()
    monkeypatch.setattr("sys.stderr", tty)
    log.setup(0)
    bar = progress(5, "points", unit="point")
    bar.update(1)
    time.sleep(0.15)  # tqdm redraws at most every 0.1 s
    bar.update(1)
    bar.close()
    assert "2/5" in tty.getvalue() and "point" in tty.getvalue()


@pytest.mark.slow
def test_a_terminal_that_reports_no_size_still_shows_the_bar() -> None:
    """A bare pseudo-terminal (0 x 0, as test harnesses and supervisors open) once made
    tqdm draw nothing at all."""
    import os
    import pty
    import select
    import subprocess
    import sys

    master, slave = pty.openpty()
    code = ("import time; from relrl.progress import progress; p = progress(10, 'x', "
            "unit='point'); p.update(1); time.sleep(0.3); p.update(1); time.sleep(0.3)")
    proc = subprocess.Popen([sys.executable, "-c", code], stderr=slave)
    os.close(slave)
    text = b""
    while proc.poll() is None or select.select([master], [], [], 0.1)[0]:
        if select.select([master], [], [], 0.1)[0]:
            try:
                text += os.read(master, 4096)
            except OSError:
                break
    os.close(master)
    assert b"2/10" in text, text


def test_quiet_means_no_progress(monkeypatch) -> None:
    err = io.StringIO()
    monkeypatch.setattr("sys.stderr", err)
    log.setup(-1)
    try:
        bar = progress(3, "x", interval=0.0)
        bar.update(3)
        bar.close()
        logging.getLogger("relrl.test").warning("a warning still shows")
        assert err.getvalue() == "relrl: a warning still shows\n"
    finally:
        log.setup(0)


@pytest.mark.slow
def test_a_session_writes_its_log_file(tmp_path: Path, capsys) -> None:
    script = episode(tmp_path, steps=20, perception="symbolic",
                     extra="[evaluation]\nevery = 10\nruns = 1\nsteps = 5\n")
    out = tmp_path / "out"
    assert main(["run", "-q", str(script), "--out", str(out), "--no-plots"]) == 0
    assert "evaluation after" not in capsys.readouterr().err  # -q: warnings only
    text = (out / "run.log").read_text()
    assert "session started" in text and "evaluation after 10 steps" in text
    assert main(["-v", "run", str(script), "--out", str(tmp_path / "o2"), "--no-plots"]) == 0
    assert "evaluation after 10 steps" in capsys.readouterr().err


def test_progress_grows_when_more_work_comes(monkeypatch) -> None:
    """grow(n): n more pieces than the total said (a job learning again); an unknown total
    stays unknown."""
    err = io.StringIO()
    monkeypatch.setattr("sys.stderr", err)
    log.setup(0)
    bar = progress(5, "points", unit="point", interval=0.0)
    bar.grow(3)
    bar.update(8)
    assert bar.total == 8 and "8/8" in err.getvalue().splitlines()[-1]
    bar.close()
    unknown = progress(None, "points", interval=0.0)
    unknown.grow(2)
    assert unknown.total is None
    unknown.close()
