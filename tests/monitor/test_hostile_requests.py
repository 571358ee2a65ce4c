"""What any client can send, and what a recording can hold, answered without a 500 or a
traceback -- on real sockets on loopback, with real symbolic links and files.

``REPLAY_CASES`` (requests to ``relrl replay``'s server over recordings that load) and
``LIVE_CASES`` (requests to a live session's server) hold 27 cases: each is a request and the
status it must get; no answer is ever a 500, and nothing is logged as an error.
"""

from __future__ import annotations

import http.client
import json
import logging

import numpy as np
import pytest

from relrl.monitor import Hub, start_live, start_replay
from tests.monitor.conftest import trace_line, write_recording

EVIL = '<<TABLE HREF="javascript:void(window.name=\'pwned\')"><TR><TD>look</TD></TR></TABLE>>'
#: labels of the kinds dot refused, or that reached it as markup.
LABELS = [EVIL, "<<b>>", "a\x00b", "a\\", "x" * 100_000, "line\n" * 5000, "a\udc80b"]
DIGITS = "7" * 5000


def _get(port: int, path: str, headers: dict | None = None) -> tuple[int, dict, bytes]:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=20)
    try:
        conn.request("GET", path, headers=headers or {})
        resp = conn.getresponse()
        if resp.getheader("content-type", "").startswith("text/event-stream"):
            body = b""
            while b"data: " not in body and (line := resp.readline()):
                body += line
            return resp.status, dict(resp.getheaders()), body + resp.readline()
        return resp.status, dict(resp.getheaders()), resp.read()
    finally:
        conn.close()


def _tree(label: str) -> str:
    return json.dumps({"t": 1, "graph": {
        "nodes": [{"id": EVIL, "kind": "test", "label": label},
                  {"id": 1, "kind": "<x>", "label": label}],
        "edges": [{"from": EVIL, "to": 1, "branch": label},
                  {"from": 1, "to": "nowhere", "branch": "no"}]}}) + "\n"


NAN_TRACE = "".join(trace_line(t, reward=float("nan"), activation={"socialize": float("nan")},
                               explanation={"ranked": [{"response": "look(left)",
                                                        "q": float("nan")}]}) + "\n"
                    for t in (1, 2, 3))

#: (name, recording changes, path, status): a request to the replay server.
REPLAY_CASES: list[tuple[str, dict[str, str], str, int]] = [
    ("nan-rows-series", {"trace.jsonl": NAN_TRACE}, "/api/series", 200),
    ("nan-rows-step", {"trace.jsonl": NAN_TRACE}, "/api/step/2", 200),
    ("tree-label-html-link", {"trees.jsonl": _tree(EVIL)}, "/tree.svg", 200),
    ("tree-label-bad-html", {"trees.jsonl": _tree("<<b>>")}, "/tree.svg", 200),
    ("tree-label-nul", {"trees.jsonl": _tree("a\x00b")}, "/tree.svg", 200),
    ("tree-label-odd-backslash", {"trees.jsonl": _tree("a\\")}, "/tree.svg", 200),
    ("tree-label-100000-chars", {"trees.jsonl": _tree("x" * 100_000)}, "/tree.svg", 200),
    ("tree-label-5000-lines", {"trees.jsonl": _tree("line\n" * 5000)}, "/tree.svg", 200),
    ("tree-label-surrogate", {"trees.jsonl": _tree("a\udc80b")}, "/tree.svg", 200),
    ("tree-t-superscript-two", {}, "/tree.svg?t=%C2%B2", 400),
    ("tree-t-5000-digits", {}, f"/tree.svg?t={DIGITS}", 400),
    ("tree-t-word", {}, "/tree.svg?t=one", 400),
    ("api-tree-label-html-link", {"trees.jsonl": _tree(EVIL)}, "/api/tree", 200),
    ("api-tree-label-5000-lines", {"trees.jsonl": _tree("line\n" * 5000)}, "/api/tree", 200),
    ("api-tree-label-surrogate", {"trees.jsonl": _tree("a\udc80b")}, "/api/tree", 200),
    ("api-tree-t-superscript-two", {}, "/api/tree?t=%C2%B2", 400),
    ("api-tree-t-5000-digits", {}, f"/api/tree?t={DIGITS}", 400),
    ("step-5000-digits", {}, f"/api/step/{DIGITS}", 404),
    ("step-superscript-two", {}, "/api/step/%C2%B2", 404),
    ("step-negative", {}, "/api/step/-1", 404),
    ("frame-5000-digits", {}, f"/frames/{DIGITS}.jpg", 404),
    ("frame-arabic-indic-digit", {}, "/frames/%D9%A1.jpg", 404),
]
#: (name, path, status): a request to a live session's server (its tree has an evil label).
LIVE_CASES: list[tuple[str, str, int]] = [
    ("live-tree-t-superscript-two", "/tree.svg?t=%C2%B2", 400),
    ("live-tree-evil-label", "/tree.svg", 200),
    ("live-api-tree-evil-label", "/api/tree", 200),
    ("live-step-5000-digits", f"/api/step/{DIGITS}", 404),
    ("live-nan-events", "/api/events", 200),
]


def test_the_corpus_holds_the_cases_it_says() -> None:
    said = int(__doc__.split(" hold ")[1].split()[0])
    assert said == len(REPLAY_CASES) + len(LIVE_CASES)


@pytest.mark.parametrize("changes, path, status", [c[1:] for c in REPLAY_CASES],
                         ids=[c[0] for c in REPLAY_CASES])
def test_replay_answers_without_a_500(tmp_path, caplog, changes, path, status) -> None:
    folder = write_recording(tmp_path / "rec", **changes)
    with caplog.at_level(logging.WARNING), start_replay(folder) as server:
        got, headers, body = _get(server.port, path)
    assert got == status, (got, body[:300])
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR], caplog.text
    if headers.get("content-type", "").startswith("application/json"):
        json.loads(body, parse_constant=lambda c: pytest.fail(f"{c} in the JSON"))
    if path.startswith("/tree.svg") and status == 200:
        _assert_inert_svg(headers, body)
    if path.startswith("/api/tree") and status == 200:
        _assert_inert_tree(body)


def _assert_inert_tree(body: bytes) -> None:
    """The page's copy of the tree: the same inert SVG, the names of both nodes."""
    tree = json.loads(body)
    svg = tree["svg"]
    assert svg.count('class="node"') == 2, svg[:2000]
    assert "href" not in svg and "<a " not in svg and "<script" not in svg
    assert sorted(tree["names"].values()) == ["n0", "n1"] and tree["parents"] == {"n1": "n0"}


def _assert_inert_svg(headers: dict, body: bytes) -> None:
    """The SVG links nowhere and runs nothing, and is served so even opened on its own."""
    svg = body.decode()
    assert svg.count('class="node"') == 2, svg[:2000]
    assert "href" not in svg and "<a " not in svg and "<script" not in svg
    csp = headers.get("content-security-policy", "")
    assert "sandbox" in csp and "default-src 'none'" in csp and "script-src" not in csp
    assert headers.get("x-content-type-options") == "nosniff"


@pytest.fixture(scope="module")
def live_server():
    hub = Hub(rate=50, info={"episode": "hostile"})
    nan = float("nan")
    hub.tick(1, [nan], nan)
    hub.publish({"t": 1, "reward": nan, "explanation": {"ranked": [{"q": nan}]}},
                np.full((24, 32, 3), 90, np.uint8))
    hub.set_tree(json.loads(_tree(EVIL))["graph"])
    with start_live(hub) as server:
        yield server


@pytest.mark.parametrize("path, status", [c[1:] for c in LIVE_CASES],
                         ids=[c[0] for c in LIVE_CASES])
@pytest.mark.slow
def test_a_live_session_answers_without_a_500(live_server, capfd, path, status) -> None:
    got, headers, body = _get(live_server.port, path)
    assert got == status, (got, body[:300])
    if path == "/api/events":
        msg = json.loads(body.decode().split("data: ", 1)[1],
                         parse_constant=lambda c: pytest.fail(f"{c} in the event"))
        assert msg["view"]["reward"] is None and msg["series"] == [[1, [None], None]]
    if path == "/tree.svg":
        _assert_inert_svg(headers, body)
    if path == "/api/tree":
        _assert_inert_tree(body)
    err = capfd.readouterr().err  # the server's process writes to this terminal too
    assert "Traceback" not in err and "Exception" not in err, err


def test_a_frame_linked_out_of_the_recording_is_not_served(tmp_path) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text("the lab's password\n")
    folder = write_recording(tmp_path / "rec")
    (folder / "frames" / "000001.jpg").unlink()
    (folder / "frames" / "000001.jpg").symlink_to(secret)
    with start_replay(folder) as server:
        status, _, body = _get(server.port, "/frames/1.jpg")
    assert status == 404 and b"password" not in body


def test_a_frame_that_is_a_fifo_is_not_served(tmp_path) -> None:
    import os

    folder = write_recording(tmp_path / "rec")
    (folder / "frames" / "000001.jpg").unlink()
    os.mkfifo(folder / "frames" / "000001.jpg")  # reading it would wait for ever
    with start_replay(folder) as server:
        assert _get(server.port, "/frames/1.jpg")[0] == 404


def test_a_frame_of_the_recording_is_served(tmp_path) -> None:
    folder = write_recording(tmp_path / "rec")
    with start_replay(folder) as server:
        status, headers, body = _get(server.port, "/frames/1.jpg")
    assert status == 200 and body[:2] == b"\xff\xd8"
    assert headers["content-type"] == "image/jpeg"
    assert "frame-ancestors 'none'" in headers.get("content-security-policy", "")


def test_an_unsorted_trace_replays_every_time_unit(tmp_path) -> None:
    folder = write_recording(tmp_path / "rec", **{
        "trace.jsonl": "".join(trace_line(t) + "\n" for t in (3, 1, 2))})
    with start_replay(folder) as server:
        for t in (1, 2, 3):
            status, _, body = _get(server.port, f"/api/step/{t}")
            assert status == 200 and json.loads(body)["t"] == t
        info = json.loads(_get(server.port, "/api/info")[2])
    assert (info["first"], info["last"]) == (1, 3)


def test_a_tree_dot_cannot_draw_is_said_not_a_500(tmp_path, monkeypatch, caplog) -> None:
    """Without Graphviz's dot the tree is a 422 that says why; the server goes on."""
    folder = write_recording(tmp_path / "rec")
    monkeypatch.setenv("PATH", str(tmp_path))  # no dot on it
    with caplog.at_level(logging.WARNING), start_replay(folder) as server:
        status, _, body = _get(server.port, "/tree.svg")
        assert _get(server.port, "/api/info")[0] == 200
    assert status == 422 and b"dot program is missing" in body
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR], caplog.text


@pytest.mark.parametrize("header, host", [
    ("[::1]", "::1"), ("[::1]:8080", "::1"), ("localhost", "localhost"),
    ("LocalHost:80", "localhost"), ("127.0.0.1:9", "127.0.0.1"), ("[::1", ""),
    ("evil.example:80", "evil.example"), ("::1", "::1")])
def test_the_host_of_a_host_header(header: str, host: str) -> None:
    from relrl.monitor.server import host_of

    assert host_of(header) == host


@pytest.mark.parametrize("header, status", [
    ("[::1]", 200), ("[::1]:{port}", 200), ("localhost", 200), ("LOCALHOST:{port}", 200),
    ("127.0.0.1", 200), ("evil.example", 403), ("127.0.0.1.evil.example", 403),
    ("[::1", 403), ("", 403)])
def test_loopback_host_headers(tmp_path, header: str, status: int) -> None:
    folder = write_recording(tmp_path / "rec")
    with start_replay(folder) as server:
        got = _get(server.port, "/api/info", {"Host": header.format(port=server.port)})[0]
    assert got == status


def test_every_answer_carries_the_security_headers(tmp_path) -> None:
    folder = write_recording(tmp_path / "rec")
    with start_replay(folder) as server:
        for path in ("/", "/api/info", "/static/monitor.js", "/frames/1.jpg", "/nope",
                     "/tree.svg"):
            _, headers, _ = _get(server.port, path)
            assert headers.get("x-content-type-options") == "nosniff", path
            csp = headers.get("content-security-policy", "")
            assert "default-src 'none'" in csp and "unsafe-eval" not in csp, path
        status, _, _ = _get(server.port, "/api/info", {"Host": "evil.example"})
        assert status == 403


@pytest.mark.parametrize("headers, status", [
    ({"Origin": "https://evil.example.com"}, 403),
    ({"Origin": "null"}, 403),
    ({"Origin": "http://127.0.0.1:1"}, 403),
    ({"Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "no-cors"}, 403),  # <img>, <script>
    ({"Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "cors"}, 403),
    ({"Origin": "http://{here}", "Sec-Fetch-Site": "same-origin"}, 200),
    ({"Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "navigate"}, 200),  # a link followed
    ({"Sec-Fetch-Site": "none"}, 200), ({}, 200)])
def test_a_web_pages_request_from_another_origin_is_refused(tmp_path, headers: dict,
                                                            status: int) -> None:
    folder = write_recording(tmp_path / "rec")
    with start_replay(folder) as server:
        sent = {k: v.format(here=f"127.0.0.1:{server.port}") for k, v in headers.items()}
        for path in ("/api/info", "/frames/1.jpg", "/api/series"):
            assert _get(server.port, path, sent)[0] == status, path


def test_a_live_session_refuses_another_origin(live_server) -> None:
    evil = {"Origin": "https://evil.example.com"}
    for path in ("/api/events", "/frame.jpg", "/api/info"):
        assert _get(live_server.port, path, evil)[0] == 403, path
    assert _get(live_server.port, "/frame.jpg")[0] == 200


def test_a_websocket_to_the_monitor_is_refused(live_server) -> None:
    import socket

    with socket.create_connection(("127.0.0.1", live_server.port), timeout=5) as sock:
        sock.sendall(f"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1:{live_server.port}\r\n"
                     "Upgrade: websocket\r\nConnection: Upgrade\r\n"
                     "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                     "Sec-WebSocket-Version: 13\r\n\r\n".encode())
        assert not sock.recv(200).startswith(b"HTTP/1.1 101")


@pytest.mark.slow
def test_the_xss_label_does_not_run_in_a_browser(page, tmp_path) -> None:
    """The issue's exploit: a branch label of HTML-like form became a javascript: link in
    /tree.svg, and clicking it in Chromium ran script. Now the label is text, and the SVG's
    own policy would stop a script anyway."""
    folder = write_recording(tmp_path / "rec", **{"trees.jsonl": _tree(EVIL)})
    with start_replay(folder) as server:
        page.goto(server.url.rstrip("/") + "/tree.svg")
        page.wait_for_selector("svg")
        for target in page.locator("a").all() + page.locator("text").all()[:3]:
            target.click()
        page.wait_for_timeout(300)
        assert page.evaluate("window.name") != "pwned", "the label's script ran"
        assert page.locator("a").count() == 0
        # the page itself runs under its policy and draws the tree
        messages: list[str] = []
        page.on("console", lambda m: messages.append(m.text))
        page.goto(server.url)
        page.wait_for_selector("#tree:not([hidden])")
        assert page.evaluate("window.name") != "pwned" and not page.errors
        assert not [m for m in messages if "Content Security Policy" in m], messages



@pytest.mark.slow
def test_the_pictures_policy_alone_stops_a_link_script(page, tmp_path, monkeypatch) -> None:
    """The second line of defence: with the labels' escaping taken away, the link is in the
    SVG -- and the SVG's content-security policy (a sandbox, no script) stops it."""
    import relrl.monitor.graph as graph

    monkeypatch.setattr(graph, "_text", lambda text, width=0: str(text))
    folder = write_recording(tmp_path / "rec", **{"trees.jsonl": _tree(EVIL)})
    with start_replay(folder) as server:
        page.goto(server.url.rstrip("/") + "/tree.svg")
        page.wait_for_selector("svg")
        assert page.locator("a").count() >= 1  # the markup went through
        page.locator("a").first.click()
        page.wait_for_timeout(300)
        assert page.evaluate("window.name") != "pwned"



@pytest.mark.slow
def test_the_pages_copy_of_the_tree_holds_no_link(page, tmp_path, monkeypatch) -> None:
    """The page draws the tree inside itself: with the labels' escaping taken away, the
    link reaches /api/tree's SVG -- and the page copies only drawing elements and their
    geometry, so no link, script or style of it is in the page."""
    import relrl.monitor.graph as graph

    monkeypatch.setattr(graph, "_text", lambda text, width=0: str(text))
    folder = write_recording(tmp_path / "rec", **{"trees.jsonl": _tree(EVIL)})
    with start_replay(folder) as server:
        page.goto(server.url)
        page.wait_for_selector("#tree svg g.node")
        svg = page.evaluate("async () => (await (await fetch('api/tree')).json()).svg")
        assert "<a " in svg and "javascript:" in svg  # the markup went through the server
        assert page.locator("#tree a").count() == 0
        assert "javascript" not in page.inner_html("#tree")
        for target in page.locator("#tree text").all()[:6]:
            target.click(force=True)
        page.wait_for_timeout(300)
        assert page.evaluate("window.name") != "pwned" and not page.errors
