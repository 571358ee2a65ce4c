"""Replay in a real headless browser: scrub through a recorded session; the player says
what it does, the tree marks each time unit's leaf and pans and zooms, the evaluations are a
curve; screenshots compared by what they show."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from relrl.episodes import RunOptions, load_episode, run_episode
from relrl.monitor import start_replay
from relrl.recording.reader import open_recording
from tests.monitor.conftest import episode, screen, wait_until

#: the recorded episode's evaluations: at the start and every 40 time units (t 0, 40, 80).
EVALUATION = "[evaluation]\nevery = 40\nruns = 2\nsteps = 15\n"


@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("recorded")
    script = episode(tmp, steps=80, extra=EVALUATION)
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


@pytest.mark.slow
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


@pytest.mark.slow
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


def _view_box(page) -> list[float]:
    return [float(x) for x in page.get_attribute("#tree svg", "viewBox").split()]


@pytest.mark.slow
def test_replay_opens_paused_and_says_so(page, recorded: Path, tmp_path: Path) -> None:
    with start_replay(recorded) as server:
        page.goto(server.url)
        _wait_text(page, "#scrub-label", "t 1 of 80")
        _wait_text(page, "#status", "press ▶")
        page.wait_for_selector("#tree svg g.node")
        shown = screen(page, tmp_path / "replay-opened.png")
        assert "Paused — press ▶ to play" in shown["status"], shown["status"]
        assert "t 1 of 80" in shown["status"]
        assert "t 1 of 80" in shown["timeline"]
        assert "look(" in shown["response-panel"]
        assert "[frame:" not in shown["camera-panel"]  # the frame of t 1, not a note
        page.click("#play")
        _wait_text(page, "#status", "Playing")
        page.wait_for_function("() => Number(document.getElementById('scrub').value) > 3")
        page.click("#play")
        _wait_text(page, "#status", "Paused")
        _scrub(page, 80)
        _wait_text(page, "#status", "At the end")
        page.keyboard.press("Space")          # at the end, play starts again from t 1
        _wait_text(page, "#status", "Playing")
        page.keyboard.press("Space")
        _wait_text(page, "#status", "Paused")
    assert not page.errors, page.errors


@pytest.mark.slow
def test_replay_marks_the_leaf_and_its_path(page, recorded: Path) -> None:
    rec = open_recording(recorded)
    with start_replay(recorded) as server:
        page.goto(server.url)
        _wait_text(page, "#scrub-label", "t 1 of 80")
        page.wait_for_selector("#tree svg g.node")
        marked = 0
        for t in (5, 17, 45, 79):
            _scrub(page, t)
            _wait_text(page, "#scrub-label", f"t {t} of 80")
            row = rec.row(t)
            leaf = row["explanation"]["leaf"]
            names = page.evaluate(f"""async () => (await (await fetch('api/tree?t={t}'))
                                  .json()).names""")
            wait_until(lambda leaf=leaf, names=names: page.get_attribute(
                "#tree-box", "data-leaf") == names.get(str(leaf)), 15, f"the leaf of t {t}")
            path = len(row["explanation"]["path"])
            assert int(page.get_attribute("#tree-box", "data-path")) == path
            assert page.locator("#tree g.node.current").count() == 1
            assert page.locator("#tree g.node.on-path").count() == path
            assert page.locator("#tree g.edge.on-path").count() == path
            marked += path
        assert marked > 0, "no time unit was below the root"
        legend = page.inner_text("#leaf-legend")
        assert "[socialize]" in legend and "necessity" in legend and "null" in legend
    assert not page.errors, page.errors


@pytest.mark.slow
def test_the_tree_pans_zooms_and_fits(page, recorded: Path) -> None:
    with start_replay(recorded) as server:
        page.goto(server.url)
        _wait_text(page, "#scrub-label", "t 1 of 80")
        _scrub(page, 80)
        _wait_text(page, "#scrub-label", "t 80 of 80")
        page.wait_for_selector("#tree svg g.node")
        # the picture of t 80, not t 1's still shown while t 80's is fetched (on a loaded
        # machine it came after the fit was read, and the fit of the new picture differed)
        want = page.evaluate("""async () => {
            const d = await getJSON("api/tree", { t: 80 });
            return d.svg.match(/viewBox="([^"]+)"/)[1].split(/[\\s,]+/).map(Number); }""")
        wait_until(lambda: page.evaluate("() => tree.base") == want, 15, "the tree of t 80")
        page.locator("#tree-box").scroll_into_view_if_needed()
        box = page.locator("#tree-box").bounding_box()
        base = page.evaluate("() => tree.base")
        fitted = _view_box(page)
        # unclipped: the whole picture is inside the view
        assert fitted[0] <= base[0] and fitted[1] <= base[1]
        assert fitted[0] + fitted[2] >= base[0] + base[2] - 1e-6
        assert fitted[1] + fitted[3] >= base[1] + base[3] - 1e-6
        cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(cx, cy)
        page.mouse.wheel(0, -400)                      # zoom in under the pointer
        wait_until(lambda: _view_box(page)[2] < fitted[2] * 0.8, 5, "a zoom")
        zoomed = _view_box(page)
        page.mouse.move(cx, cy)
        page.mouse.down()
        page.mouse.move(cx + 120, cy + 60, steps=4)    # drag: the picture follows
        page.mouse.up()
        moved = _view_box(page)
        assert moved[0] < zoomed[0] and moved[1] < zoomed[1] and moved[2] == zoomed[2]
        page.click("#tree-fit")
        assert _view_box(page) == fitted
        page.check("#tree-follow")                     # centred on the current leaf
        leaf = page.locator("#tree g.node.current").bounding_box()
        assert abs(leaf["x"] + leaf["width"] / 2 - cx) < 3
    assert not page.errors, page.errors


@pytest.mark.slow
def test_the_evaluations_are_a_curve(page, recorded: Path, tmp_path: Path) -> None:
    rec = open_recording(recorded)
    evaluations = [e for e in rec.events if e["kind"] == "evaluation"]
    assert [e["t"] for e in evaluations] == [0, 40, 80]
    with start_replay(recorded) as server:
        page.goto(server.url)
        _wait_text(page, "#scrub-label", "t 1 of 80")
        assert int(page.get_attribute("#cgi-plot", "data-points")) == 3
        _scrub(page, 50)
        _wait_text(page, "#scrub-label", "t 50 of 80")
        shown = screen(page, tmp_path / "replay-evaluations.png")
        second = evaluations[1]
        assert (f"last: CGI {second['cgi_mean']:.2f} ± {second['cgi_std']:.2f} at t 40 "
                "(after 40 time units of learning)") in shown["metrics-panel"]
    assert not page.errors, page.errors


def test_the_recorded_tree_holds_each_units_leaf(recorded: Path) -> None:
    """The tree is recorded when a step's leaf is not in the last one (a split), not only
    once a second: at every time unit the tree replay shows holds the leaf the response
    came from, at the depth of its explanation's path."""
    rec = open_recording(recorded)
    for row in rec.rows:
        graph, e = rec.tree_at(row["t"]), row["explanation"]
        parent = {str(x["to"]): str(x["from"]) for x in graph["edges"]}
        kinds = {str(n["id"]): n["kind"] for n in graph["nodes"]}
        node, depth = str(e["leaf"]), 0
        while node in parent:
            node, depth = parent[node], depth + 1
        assert kinds.get(str(e["leaf"])) == "leaf", row["t"]
        assert depth == len(e["path"]), row["t"]
