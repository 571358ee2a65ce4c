"""The README's first hour, run as written.

Every line of the README's "Your first hour" block is run verbatim by ``bash`` in a fresh
folder that holds the checkout's ``.venv`` and ``examples`` (as a checkout would), in order,
each depending on what the ones before wrote. Two lines are the set-up rather than relrl, and
are checked instead of run: ``make demo`` (the Makefile's ``demo`` recipe must be
``relrl demo``, which is then run verbatim), and the ``pip install`` of extras (each extra
must be declared, and its packages importable here: ``make test`` installs them). Commands
that serve a page are checked while they serve it: the live monitor's page and the replay's
answer over HTTP, and the replay ends on Ctrl-C with exit status 0.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import tomllib
import urllib.request
from pathlib import Path

import pytest

from tests.conftest import ROOT, default_signals

URL = re.compile(r"(http://127\.0\.0\.1:\d+/\S*)")


def _first_hour_block(language: str) -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Your first hour", 1)[1].split("\n## ", 1)[0]
    block = re.search(rf"```{language}\n(.*?)```", section, re.S)
    assert block, f"README.md: no ```{language} block under 'Your first hour'"
    return block[1]


def first_hour_commands() -> list[str]:
    """The command lines of the README's first hour, as written."""
    return [line for line in _first_hour_block("sh").splitlines() if line.strip()]


@pytest.mark.slow
def test_the_first_hour_python_runs_as_written(tmp_path: Path) -> None:
    """The README's own-code example learns gaze following (tg's first test) in 2,000 units."""
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    (tmp_path / "example.py").write_text(_first_hour_block("python"))
    proc = subprocess.run([sys.executable, "example.py"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "gaze(face, P), action(look(P))" in proc.stdout, proc.stdout


def _get(url: str) -> str:
    with urllib.request.urlopen(url, timeout=20) as response:   # noqa: S310 (localhost)
        assert response.status == 200
        return response.read().decode("utf-8", "replace")


def _serve_and_read(line: str, cwd: Path, *, interrupt: bool) -> str:
    """Run a command that prints its page's address; fetch the page while it serves; stop
    it with Ctrl-C (``interrupt``) or let it end. Returns its whole output."""
    # Ctrl-C as at a terminal: a suite started in the background (`make test &`) runs with
    # SIGINT ignored, and an ignored signal is inherited
    proc = subprocess.Popen(["bash", "-c", f"exec {line}"], cwd=cwd, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True, preexec_fn=default_signals)
    assert proc.stdout is not None
    out = []
    try:
        for text in proc.stdout:
            out.append(text)
            if m := URL.search(text):
                assert "<html" in _get(m[1]).lower()
                break
        else:
            pytest.fail(f"{line}: printed no address:\n{''.join(out)}")
        if interrupt:
            proc.send_signal(signal.SIGINT)
        rest, _ = proc.communicate(timeout=300)
        out.append(rest)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 0, f"{line}: exit {proc.returncode}\n{''.join(out)}"
    return "".join(out)


@pytest.mark.slow
def test_every_first_hour_command_runs_as_written(tmp_path: Path) -> None:
    (tmp_path / ".venv").symlink_to(ROOT / ".venv")
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    lines = first_hour_commands()
    assert len(lines) >= 6
    outputs: dict[str, str] = {}
    for line in lines:
        command = line.split("  #")[0].strip()
        if command == "make demo":
            recipe = (ROOT / "Makefile").read_text().split("\ndemo:", 1)[1].splitlines()[1]
            assert recipe.strip() == "$(BIN)/relrl demo", recipe
            command = ".venv/bin/relrl demo"
        if "pip install" in command:
            extras = re.search(r"\.\[([\w,]+)\]", command)
            assert extras, command
            declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
                "optional-dependencies"]
            for extra in extras[1].split(","):
                assert extra in declared, f"{command}: no extra {extra!r} in pyproject.toml"
            import mcap  # noqa: F401  (the monitor's and the recordings' packages are here)
            import starlette  # noqa: F401
            continue
        if "--monitor" in command:
            outputs[command] = _serve_and_read(command, tmp_path, interrupt=False)
            continue
        if " replay " in command:
            outputs[command] = _serve_and_read(command, tmp_path, interrupt=True)
            continue
        proc = subprocess.run(["bash", "-c", command], cwd=tmp_path, capture_output=True,
                              text=True, timeout=600)
        assert proc.returncode == 0, f"{command}: exit {proc.returncode}\n{proc.stderr}"
        assert "Traceback" not in proc.stderr, proc.stderr
        outputs[command] = proc.stdout

    text = "\n".join(outputs.values())
    assert "CGI" in text and "etg" in text and "tg" in text            # the demo's table
    assert (tmp_path / "runs" / "watch" / "session.mcap").stat().st_size > 0
    assert (tmp_path / "runs" / "watch" / "policy.pl").is_file()
    assert re.search(r"leaf \[\d+\] state \d+", text)                  # the tree, as text
    assert re.search(r"R = look\(\w+\)", text)                        # a query's answers
    assert "is valid" in text                                          # the copied domain

    # the demo and `relrl report` on its run (runs/demo-YYYYMMDD-HHMMSS) count the same
    # evaluation points
    demo = re.search(r"(\d+) evaluation points", outputs[".venv/bin/relrl demo"])
    runs = sorted((tmp_path / "runs").glob("demo-*"))
    assert len(runs) == 1, runs
    report = subprocess.run([".venv/bin/relrl", "report", str(runs[0].relative_to(tmp_path))],
                            cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert report.returncode == 0, report.stderr
    counted = re.search(r"(\d+) evaluation points", report.stdout)
    assert demo and counted, (outputs[".venv/bin/relrl demo"], report.stdout)
    assert demo[1] == counted[1], (demo[0], counted[0])
