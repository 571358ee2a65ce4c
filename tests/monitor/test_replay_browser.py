"""Replay in a real headless browser: scrub through a recorded session."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from relrl.episodes import RunOptions, load_episode, run_episode
from relrl.monitor import start_replay
from relrl.recording.reader import open_recording
from tests.monitor.conftest import episode


@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("recorded")
    script = episode(tmp, steps=80)
    out = tmp / "session"
    run_episode(load_episode(script), RunOptions(out=out, head="sim", plots=False,
                                                 record=True, record_rate=0))
    return out


def _wait_text(page, selector: str, text: str, timeout: float = 15.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if text in page.inner_text(selector):
            return
        time.sleep(0.05)
    raise AssertionError(f"{selector} never showed {text!r}: {page.inner_text(selector)!r}")


def _scrub(page, t: int) -> None:
    page.evaluate(f"""() => {{ const s = document.getElementById('scrub'); s.value = {t};
        s.dispatchEvent(new Event('input')); }}""")


def test_scrubbing_shows_each_time_unit(page, recorded: Path, tmp_path: Path) -> None:
    rec = open_recording(recorded)  # its session.mcap
    with start_replay(recorded) as server:
        page.goto(server.url)
        page.wait_for_selector("#mode.replay")
        assert page.is_visible("#timeline")
        _wait_text(page, "#scrub-label", "t 1 of 80")
        drawn = int(page.get_attribute("#frame", "data-frames-drawn") or 0)
        for t in (40, 7, 80):
            _scrub(page, t)
            _wait_text(page, "#scrub-label", f"t {t} of 80")
            row = rec.row(t)
            assert page.inner_text("#t") == str(t)
            assert page.inner_text("#response") == row["response"]
            assert page.get_attribute("#explanation", "data-t") == str(t)
            percepts = page.inner_text("#percepts")
            assert all(p in percepts for p in row["percepts"])
            deadline = time.monotonic() + 10
            while page.get_attribute("#frame", "data-frame-seq") != str(row["frame"]):
                assert time.monotonic() < deadline, "the frame of the time unit never came"
                time.sleep(0.05)
        assert int(page.get_attribute("#frame", "data-frames-drawn")) >= drawn + 3
        page.keyboard.press("ArrowLeft")
        _wait_text(page, "#scrub-label", "t 79 of 80")
        assert int(page.get_attribute("#plot", "data-points")) == 80
        page.wait_for_selector("#tree:not([hidden])")
        page.screenshot(path=str(tmp_path / "replay.png"), full_page=True)
    assert (tmp_path / "replay.png").stat().st_size > 10_000
    assert not page.errors, page.errors


def test_the_recorded_folder_is_self_contained(recorded: Path) -> None:
    manifest = json.loads((recorded / "session.json").read_text())
    for name in manifest["files"].values():
        assert (recorded / name).is_file(), name
    assert (recorded / "episode.toml").read_text().count('domain = "domain.pl"') == 1
    # the copied script runs from the folder alone
    ep = load_episode(recorded / "episode.toml")
    assert ep.domain.resolve() == (recorded / "domain.pl").resolve()
    assert manifest["recording"]["frames"] == 81       # every unit, and the last view
    rec = open_recording(recorded)
    assert len(rec.frames) == 81 and rec.manifest == manifest
    assert manifest["necessities"] == ["socialize"]
    assert rec.trees[-1]["graph"]["nodes"]
