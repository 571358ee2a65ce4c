"""The live monitor in a real headless browser: a simulator run with ``--monitor``, from its
first seconds (the initial evaluation) through learning and an evaluation; screenshots
compared by what they show."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest

from tests.monitor.conftest import episode, screen, wait_until

pytestmark = pytest.mark.slow  # every test here takes a second or more


def _attr(page, selector: str, name: str) -> int:
    return int(page.get_attribute(selector, name) or 0)


def _activity(page) -> str:
    return page.get_attribute("#status", "data-activity") or ""


def test_live_page_from_its_first_seconds(page, relrl_process, tmp_path: Path) -> None:
    # stopped by Ctrl-C once the page has shown an evaluation during learning
    script = episode(tmp_path, steps=2000,
                     extra="[evaluation]\nevery = 60\nruns = 2\nsteps = 40\n")
    proc = relrl_process("run", str(script), "--monitor", "--monitor-rate", "8",
                         "--head", "sim", "--step-seconds", "0.03", "--no-plots")
    url = proc.url()
    assert url.startswith("http://127.0.0.1:")
    page.goto(url)
    page.wait_for_selector("#mode.live")
    # the first seconds: no frame and no time unit yet, and the page says why
    wait_until(lambda: _activity(page) == "initial evaluation", 60, "the initial evaluation")
    shown = screen(page, tmp_path / "live-initial-evaluation.png")
    assert "Initial evaluation" in shown["status"] and "before any learning" in shown["status"]
    assert "run 1 of 2" in shown["status"] or "run 2 of 2" in shown["status"], shown["status"]
    assert "[frame: no frame yet · initial evaluation" in shown["camera-panel"]
    assert "[plot: no time unit of learning yet" in shown["necessity-panel"]
    assert "[cgi-plot: the initial evaluation is running" in shown["metrics-panel"]
    assert "nothing yet" in shown["response-panel"]
    assert _attr(page, "#frame", "data-frames-drawn") == 0
    # learning: frames, the plot and the explanation update; the status counts time units
    wait_until(lambda: _attr(page, "#frame", "data-frames-drawn") >= 2, 60, "two frames")
    assert _activity(page) in ("learning", "evaluating")
    frames, points = _attr(page, "#frame", "data-frames-drawn"), _attr(page, "#plot",
                                                                       "data-points")
    t_explained = _attr(page, "#explanation", "data-t")
    first_frame = page.get_attribute("#frame", "data-frame-seq")
    wait_until(lambda: _attr(page, "#frame", "data-frames-drawn") > frames + 2
               and _attr(page, "#plot", "data-points") > points
               and _attr(page, "#explanation", "data-t") > t_explained, 30, "new views")
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
    # the initial evaluation is the first point of the CGI curve
    assert _attr(page, "#cgi-plot", "data-points") >= 1
    # the tree, with the leaf of the time unit shown and its path from the root
    wait_until(lambda: page.locator("#tree svg g.node").count() > 1, 60, "a tree with tests")
    # the leaf marked, its path counted, read in one task of the page (it marks each new
    # time unit's leaf, and one not drawn yet marks nothing until the tree is redrawn)
    marks: list = []

    def leaf_marked() -> bool:
        marks[:] = page.evaluate("""() => [
            document.querySelectorAll('#tree g.node.current').length,
            document.querySelectorAll('#tree g.node.on-path').length,
            Number(document.getElementById('tree-box').dataset.path)]""")
        return marks[0] == 1 and marks[2] >= 1

    wait_until(leaf_marked, 30, "a leaf below the root")
    assert marks[1] == marks[2], marks     # one node on the path for each step from the root
    # an evaluation during learning is said, and then learning goes on
    wait_until(lambda: _activity(page) == "evaluating", 90, "the evaluation after 60 units")
    shown = screen(page, tmp_path / "live-evaluating.png")
    assert "Evaluating" in shown["status"] and "after 60 steps of learning" in shown["status"]
    assert "CGI" in shown["metrics-panel"] and "last: CGI" in shown["metrics-panel"]
    wait_until(lambda: _activity(page) == "learning", 60, "learning again")
    shown = screen(page, tmp_path / "live.png")
    assert "Learning" in shown["status"] and "of 2000" in shown["status"], shown["status"]
    assert "look(" in shown["response-panel"]
    assert "[none]" in shown["tree-panel"] and "necessity" in shown["tree-panel"]  # the legend
    assert "[" not in shown["camera-panel"]  # no note over the camera any more
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
    page.wait_for_selector("#tree svg g.node", timeout=30_000)
    shown = screen(page, tmp_path / "finished.png")
    assert "Finished" in shown["status"] and "after 60 of 60 steps" in shown["status"]
    assert "symbolic" in page.inner_text("#frame-note")
    assert _attr(page, "#plot", "data-points") == 60
    proc.wait_for("the monitor stays up")  # the summary is written; Ctrl-C ends the page
    proc.proc.send_signal(signal.SIGINT)
    code, out = proc.finish()
    assert code == 0, out
