"""Fixtures of the monitor's tests: a headless Chromium (Debian's, driven by Playwright; no
browser is ever downloaded), short episodes, and running ``relrl run`` in a subprocess."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from bench.episode_script import fruits_episode
from tests.conftest import default_signals

ROOT = Path(__file__).resolve().parents[2]
FRUITS = ROOT / "examples" / "domains" / "fruits.pl"
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                  "--no-first-run", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync"]


def episode(tmp_path: Path, steps: int = 200, perception: str = "render",
            extra: str = "") -> Path:
    """A short Experiment-2-like script (protocol caregiver with fruits)."""
    path = tmp_path / "short.toml"
    path.write_text(fruits_episode(FRUITS, name="short", seed=5, steps=steps,
                                   perception=perception, warm_up=10, policy_save="policy.pl",
                                   extra=extra))
    return path


@pytest.fixture(scope="session")
def chromium() -> Iterator[object]:
    """A headless Chromium (``/usr/bin/chromium``) under Playwright."""
    from playwright.sync_api import sync_playwright

    assert Path(CHROMIUM).exists(), "make test installs Debian's chromium"
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
        yield browser
        browser.close()


@pytest.fixture
def page(chromium, tmp_path: Path) -> Iterator[object]:
    """A fresh page (its own context) of 1400 x 1000 pixels; console errors collected."""
    context = chromium.new_context(viewport={"width": 1400, "height": 1000})
    pg = context.new_page()
    pg.errors = []  # type: ignore[attr-defined]
    pg.on("pageerror", lambda exc: pg.errors.append(str(exc)))  # type: ignore[attr-defined]
    yield pg
    context.close()


#: what :func:`screen` reads of the page: the header, the status line, the timeline, panels.
_SHOWN = r"""() => {
    const out = {};
    for (const el of document.querySelectorAll('header, #status, #timeline, section.panel')) {
        const r = el.getBoundingClientRect();
        if (!r.width || !r.height || el.hidden) continue;
        let text = el.innerText;
        for (const c of el.querySelectorAll('canvas'))
            if (c.dataset.note) text += `\n[${c.id}: ${c.dataset.note}]`;
        out[el.id || el.tagName.toLowerCase()] = text.replace(/\s+/g, " ").trim();
    }
    return out;
}"""


def screen(page, path: Path) -> dict[str, str]:
    """A full-page screenshot into ``path``, and what it shows: the visible text of the
    header, the status line, the timeline and each panel by its id (white space made one
    space), with the note a canvas draws when it has nothing to plot (``[frame: no frame
    yet · ...]``) -- what a test compares a screenshot by."""
    page.screenshot(path=str(path), full_page=True)
    assert path.stat().st_size > 10_000, "an empty screenshot"
    return page.evaluate(_SHOWN)


def wait_until(condition, timeout: float = 30.0, what: str = "the page") -> None:
    """Poll ``condition()`` every 0.1 s until it is true."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.1)
    raise AssertionError(f"{what} did not come in {timeout:.0f} s")


class RelrlProcess:
    """``relrl ARGS`` in a subprocess; :meth:`url` waits for the monitor's address."""

    def __init__(self, *args: str) -> None:
        self.proc = subprocess.Popen([sys.executable, "-m", "relrl", *args],
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, cwd=ROOT, preexec_fn=default_signals)
        self.lines: list[str] = []

    def wait_for(self, pattern: str, timeout: float = 60.0) -> re.Match[str]:
        """Read output lines until one matches ``pattern``."""
        deadline = time.monotonic() + timeout
        assert self.proc.stdout is not None
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            self.lines.append(line)
            m = re.search(pattern, line)
            if m:
                return m
        raise AssertionError(f"never printed {pattern!r}: " + "".join(self.lines))

    def url(self, timeout: float = 60.0) -> str:
        """The monitor's address, once printed."""
        return self.wait_for(r"(http://\S+)", timeout).group(1)

    def finish(self, timeout: float = 120.0) -> tuple[int, str]:
        out, _ = self.proc.communicate(timeout=timeout)
        return self.proc.returncode, "".join(self.lines) + out

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.communicate()


@pytest.fixture
def relrl_process() -> Iterator[type[RelrlProcess]]:
    """Start ``relrl`` subprocesses; every one still running at the end is killed."""
    started: list[RelrlProcess] = []

    def start(*args: str) -> RelrlProcess:
        p = RelrlProcess(*args)
        started.append(p)
        return p

    yield start  # type: ignore[misc]
    for p in started:
        p.kill()



class Slowloris:
    """A slowloris client on loopback in a process of its own (``bench.monitor_cost``'s),
    bounded in ``count`` and ``seconds``: ``with Slowloris(port, 300, 4) as attack: ...``
    (``attack.opened`` once the connections are made; :meth:`result` waits for the end)."""

    def __init__(self, port: int, count: int, seconds: float) -> None:
        from bench.monitor_cost import SLOWLORIS

        self.proc = subprocess.Popen([sys.executable, "-c", SLOWLORIS, str(port), str(count),
                                      str(seconds)], stdout=subprocess.PIPE, text=True)
        self.seconds = seconds
        self.opened = -1

    def __enter__(self) -> Slowloris:
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline().split()
        self.opened = int(line[1]) if line[:1] == ["opened"] else -1
        return self

    def result(self) -> tuple[int, int]:
        """``(answered, closed)`` once the attack has ended."""
        out, _ = self.proc.communicate(timeout=self.seconds + 30)
        words = out.split()
        return int(words[1]), int(words[3])

    def __exit__(self, *exc: object) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.communicate()


def _jpeg() -> bytes:
    import numpy as np

    from relrl.monitor.frames import encode_jpeg

    return encode_jpeg(np.full((24, 32, 3), 120, np.uint8))


def trace_line(t: int, **extra: object) -> str:
    """One line of a small recorded trace (valid unless ``extra`` says otherwise)."""
    import json

    row = {"t": t, "phase": "fruits", "activation": {"socialize": 0.5}, "reward": -1.0,
           "response": "look(left)", "percepts": ["see(face)"], "allowed": ["look(left)"],
           "explanation": {"learner": "etg", "path": [{"test": "stimulus(face)", "holds": True}],
                           "ranked": [{"response": "look(left)", "q": 30.0}]}, "frame": 1}
    row.update(extra)
    return json.dumps(row)


def recording_files() -> dict[str, bytes]:
    """The files of a small valid recorded session (three time units, one frame)."""
    import json

    tree = {"nodes": [{"id": "0", "kind": "test", "label": "stimulus(face)"},
                      {"id": "1", "kind": "leaf", "label": "look(left) 30.0"},
                      {"id": "2", "kind": "leaf", "label": "look(centre) 30.0"}],
            "edges": [{"from": "0", "to": "1", "branch": "yes"},
                      {"from": "0", "to": "2", "branch": "no"}]}
    return {
        "trace.jsonl": "".join(trace_line(t) + "\n" for t in (1, 2, 3)).encode(),
        "frames.jsonl": json.dumps({"index": 1, "t": 1, "file": "frames/000001.jpg"}).encode()
        + b"\n",
        "frames/000001.jpg": _jpeg(),
        "trees.jsonl": json.dumps({"t": 1, "graph": tree}).encode() + b"\n",
        "events.jsonl": json.dumps({"kind": "evaluation", "t": 2, "cgi_mean": 0.5,
                                    "cgi_std": 0.1, "on": "simulator"}).encode() + b"\n",
        "session.json": json.dumps({"episode": "small", "learner": {"name": "etg"},
                                    "necessities": ["socialize"], "seed": 1},
                                   indent=1).encode(),
        "summary.json": json.dumps({"episode": "small", "learner": {"name": "etg"}},
                                   indent=1).encode(),
    }


def write_recording(folder: Path, **changes: bytes | str | None) -> Path:
    """A small recorded session in ``folder``; ``changes`` replace files (``frames__x`` is
    ``frames/x``; ``None`` removes one)."""
    files = recording_files()
    for name, content in changes.items():
        files[name.replace("__", "/")] = content.encode() if isinstance(content, str) \
            else content  # type: ignore[assignment]
    for name, content in files.items():
        if content is None:
            continue
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content)
    return folder
