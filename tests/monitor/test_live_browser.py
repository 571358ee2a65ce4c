"""The live monitor in a real headless browser: a simulator run with ``--monitor``."""

from __future__ import annotations

import signal
import time
from pathlib import Path

from tests.monitor.conftest import episode


def _attr(page, selector: str, name: str) -> int:
    return int(page.get_attribute(selector, name) or 0)


def _wait(page, condition, timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.1)
    raise AssertionError("the page did not update in time")


def test_live_page_updates_frame_plot_and_explanation(page, relrl_process,
                                                      tmp_path: Path) -> None:
    script = episode(tmp_path, steps=2000)  # stopped by Ctrl-C once the page has updated
    proc = relrl_process("run", str(script), "--monitor", "--monitor-rate", "8",
                         "--head", "sim", "--step-seconds", "0.03", "--no-plots")
    url = proc.url()
    assert url.startswith("http://127.0.0.1:")
    page.goto(url)
    page.wait_for_selector("#mode.live")
    _wait(page, lambda: _attr(page, "#frame", "data-frames-drawn") >= 2)
    frames, points = _attr(page, "#frame", "data-frames-drawn"), _attr(page, "#plot",
                                                                       "data-points")
    t_explained = _attr(page, "#explanation", "data-t")
    first_frame = page.get_attribute("#frame", "data-frame-seq")
    _wait(page, lambda: _attr(page, "#frame", "data-frames-drawn") > frames + 2
          and _attr(page, "#plot", "data-points") > points
          and _attr(page, "#explanation", "data-t") > t_explained)
    assert page.get_attribute("#frame", "data-frame-seq") != first_frame
    # the frame is a real picture, not an empty canvas
    lit = page.evaluate("""() => { const c = document.getElementById('frame');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0; for (let i = 0; i < d.length; i += 4) n += d[i] + d[i+1] + d[i+2] > 60;
        return n / (d.length / 4); }""")
    assert lit > 0.5
    assert page.locator("#ranked tbody tr").count() >= 1
    assert page.locator("#memory tbody tr").count() >= 1
    assert page.locator("#head tbody tr").count() == 5  # the simulated head's servos
    assert "see(" in page.inner_text("#percepts")
    page.screenshot(path=str(tmp_path / "live.png"), full_page=True)
    assert (tmp_path / "live.png").stat().st_size > 10_000
    assert not page.errors, page.errors
    proc.proc.send_signal(signal.SIGINT)  # Ctrl-C: the run stops cleanly, monitor and all
    code, out = proc.finish()
    assert code == 130 and "everything up to it is written" in out, out


def test_page_says_finished_and_shows_the_tree(page, relrl_process, tmp_path: Path) -> None:
    script = episode(tmp_path, steps=60, perception="symbolic")
    proc = relrl_process("run", str(script), "--monitor", "--monitor-hold",
                         "--step-seconds", "0.02")
    url = proc.url()
    page.goto(url)
    page.wait_for_selector("#mode.finished", timeout=60_000)
    page.wait_for_selector("#tree:not([hidden])", timeout=30_000)
    # the tree's picture (an SVG drawn by Graphviz) has loaded, whatever redraw came last
    page.wait_for_function("() => { const i = document.getElementById('tree');"
                           " return i.complete && i.naturalWidth > 50; }", timeout=30_000)
    assert "symbolic" in page.inner_text("#frame-note")
    assert _attr(page, "#plot", "data-points") == 60
    proc.wait_for("the monitor stays up")  # the summary is written; Ctrl-C ends the page
    proc.proc.send_signal(signal.SIGINT)
    code, out = proc.finish()
    assert code == 0, out
