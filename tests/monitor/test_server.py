"""The monitor's server: read-only, the token off localhost, the Host check, addresses; the
hub drops what a slow reader missed."""

from __future__ import annotations

import http.client
import json
import socket

import numpy as np
import pytest

from relrl.cli import main
from relrl.errors import ConfigError
from relrl.monitor import Hub, start_live
from relrl.monitor.server import LiveSource, MonitorServer, is_loopback, parse_address

PATHS = ["/", "/api/info", "/api/events", "/frame.jpg", "/tree.svg", "/api/tree",
         "/static/monitor.js", "/static/plots.js", "/static/tree.js"]


def _request(port: int, method: str, path: str, headers: dict | None = None
             ) -> tuple[int, bytes]:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        conn.request(method, path, headers=headers or {})
        resp = conn.getresponse()
        if resp.getheader("content-type", "").startswith("text/event-stream"):
            body = b""
            while resp.status == 200 and b"data: " not in body:  # the first event
                body += resp.readline()
            return resp.status, body + resp.readline()
        return resp.status, resp.read()
    finally:
        conn.close()


def _hub() -> Hub:
    hub = Hub(rate=50, info={"episode": "test"})
    hub.tick(1, [0.5], -1.0)
    hub.publish({"t": 1, "percepts": ["see(face)"]}, np.full((24, 32, 3), 90, np.uint8))
    hub.set_tree({"nodes": [{"id": 0, "kind": "test", "label": "stimulus(face)"},
                            {"id": 1, "kind": "leaf", "label": "look(centre)"},
                            {"id": 2, "kind": "leaf", "label": "look(left)"}],
                  "edges": [{"from": 0, "to": 1, "branch": "yes"},
                            {"from": 0, "to": 2, "branch": "no"}]})
    return hub


@pytest.mark.slow
def test_every_endpoint_answers_get_and_refuses_writes() -> None:
    with start_live(_hub()) as server:
        for path in PATHS:
            status, body = _request(server.port, "GET", path)
            assert status == 200, (path, status, body[:200])
            for method in ("POST", "PUT", "DELETE", "PATCH"):
                status, body = _request(server.port, method, path)
                assert status == 405, (method, path, status)
                assert b"read-only" in body
        assert _request(server.port, "GET", "/frame.jpg")[1][:2] == b"\xff\xd8"  # a JPEG
        assert b"<svg" in _request(server.port, "GET", "/tree.svg")[1]
        tree = json.loads(_request(server.port, "GET", "/api/tree")[1])
        assert "<svg" in tree["svg"] and tree["names"] == {"0": "n0", "1": "n1", "2": "n2"}
        assert tree["parents"] == {"n1": "n0", "n2": "n0"}
        status, body = _request(server.port, "GET", "/api/events")
        msg = json.loads(body.decode().split("data: ", 1)[1])
        assert msg["view"]["t"] == 1 and msg["series"] == [[1, [0.5], -1.0]]


def test_off_localhost_every_request_needs_the_token() -> None:
    with MonitorServer(LiveSource(_hub()), "0.0.0.0:0") as server:
        assert server.token and f"token={server.token}" in server.url
        for path in PATHS:
            assert _request(server.port, "GET", path)[0] == 401, path
            assert _request(server.port, "GET", path + "?token=wrong")[0] == 401, path
            assert _request(server.port, "POST", path + f"?token={server.token}")[0] == 405
        sep = "&" if "?" in "/api/info" else "?"
        assert _request(server.port, "GET", f"/api/info{sep}token={server.token}")[0] == 200
        headers = {"Authorization": f"Bearer {server.token}"}
        assert _request(server.port, "GET", "/frame.jpg", headers)[0] == 200
        assert _request(server.port, "GET", "/tree.svg",
                        {"Cookie": f"relrl_token={server.token}"})[0] == 200


@pytest.mark.slow
def test_on_localhost_a_foreign_host_header_is_refused() -> None:
    with start_live(_hub()) as server:
        assert server.token is None
        assert _request(server.port, "GET", "/api/info", {"Host": "evil.example"})[0] == 403
        assert _request(server.port, "GET", "/api/info",
                        {"Host": f"localhost:{server.port}"})[0] == 200


def test_addresses() -> None:
    assert parse_address(None) == ("127.0.0.1", 0)
    assert parse_address("8123") == ("127.0.0.1", 8123)
    assert parse_address(":8123") == ("127.0.0.1", 8123)
    assert parse_address("0.0.0.0:80") == ("0.0.0.0", 80)
    assert parse_address("[::1]:90") == ("::1", 90)
    assert is_loopback("127.0.0.2") and is_loopback("::1") and is_loopback("localhost")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.0.2.1")
    for bad in ("host:port", "localhost:-1", "127.0.0.1:70000"):
        with pytest.raises(ConfigError):
            parse_address(bad)


def test_a_port_in_use_is_one_line(tmp_path, capsys) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        port = s.getsockname()[1]
        with pytest.raises(ConfigError, match="cannot listen"):
            start_live(Hub(), f"127.0.0.1:{port}")
        script = tmp_path / "e.toml"
        from tests.monitor.conftest import episode

        script = episode(tmp_path, steps=20, perception="symbolic")
        assert main(["run", str(script), "--monitor", f"127.0.0.1:{port}"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot listen" in err[0]


def test_bad_monitor_flags_are_one_line(tmp_path, capsys) -> None:
    from tests.monitor.conftest import episode

    script = episode(tmp_path, steps=20, perception="symbolic")
    for args in (["--monitor", "host:port"], ["--monitor-rate", "0", "--monitor"],
                 ["--record"], ["--monitor-hold"], ["--out", str(tmp_path / "o"), "--record",
                                                    "--record-quality", "0"]):
        assert main(["run", str(script), *args]) == 2, args
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("relrl run: "), (args, err)


def test_a_slow_reader_gets_only_the_newest_view() -> None:
    hub = Hub(rate=1000)
    for t in range(1, 101):
        hub.tick(t, [t / 100], 0.0)
        hub.publish({"t": t}, None)
    msg, version, count = hub.message(-1, 0)
    assert msg["view"]["t"] == 100          # the 99 views before it are dropped
    assert len(msg["series"]) == 100 and count == 100   # the plot keeps every point
    assert hub.message(version, count)[0] is None       # nothing new
    hub.tick(101, [0.0], 1.0)
    msg, _, _ = hub.message(version, count)
    assert msg["series"] == [[101, [0.0], 1.0]]


def test_the_hub_paces_views_at_its_rate() -> None:
    hub = Hub(rate=2)
    assert hub.due()
    hub.publish({"t": 1})
    assert not hub.due()   # the next view is due half a second later
    with pytest.raises(ValueError):
        Hub(rate=0)


def test_a_tree_query_out_of_time_keeps_the_last_tree(caplog) -> None:
    from relrl.errors import QueryTimeout
    from relrl.monitor.graph import shown_graph

    class Slow:
        def graph(self):
            raise QueryTimeout("query ran longer than 10 s")

    last = {"nodes": [{"id": 0, "kind": "leaf", "label": "x"}], "edges": []}
    assert shown_graph(Slow(), last) is last
    assert "the tree was not redrawn" in caplog.text


def test_the_hub_hands_over_what_the_session_does() -> None:
    """The status reaches the page before any view, and through the server's process."""
    hub = Hub(rate=50)
    hub.status("initial evaluation", "the robot before any learning", done=0, total=3)
    msg, version, count = hub.message(-1, 0)
    assert msg["view"] is None and msg["status"] == {
        "activity": "initial evaluation", "detail": "the robot before any learning",
        "done": 0, "total": 3}
    hub.status("learning", "phase 'fruits'", phase="fruits", steps=300)
    assert hub.message(version, count)[0]["status"]["activity"] == "learning"
    served = Hub(rate=50)
    served.apply(hub.changes({}))
    assert served.message(-1, 0)[0]["status"] == hub.state
    with pytest.raises(ValueError, match="unknown activity 'dreaming'"):
        hub.status("dreaming")


@pytest.mark.slow
def test_a_session_tells_the_monitor_each_thing_it_does(tmp_path) -> None:
    """Every status a session sets, in order: from its own state, not guessed."""
    from relrl.episodes import RunOptions, load_episode, run_episode
    from tests.monitor.conftest import episode

    class Recording(Hub):
        def status(self, activity, detail="", **data):
            super().status(activity, detail, **data)
            seen.append((activity, data.get("done"), data.get("phase")))

    seen: list = []
    script = episode(tmp_path, steps=30, perception="symbolic",
                     extra="[evaluation]\nevery = 20\nruns = 2\nsteps = 10\n"
                           "[naming]\nexecutions = 2\n")
    run_episode(load_episode(script), RunOptions(monitor=Recording(rate=50), plots=False))
    assert seen == [("starting", None, None),
                    ("initial evaluation", 0, None), ("initial evaluation", 1, None),
                    ("learning", None, "no objects"), ("learning", None, "fruits"),
                    ("evaluating", 0, None), ("evaluating", 1, None),
                    ("learning", None, "fruits"),
                    ("naming", 0, None), ("naming", 1, None),
                    ("finished", None, None)]


@pytest.mark.slow
def test_a_session_on_a_camera_says_it_waits_for_it(tmp_path) -> None:
    from relrl.episodes import RunOptions, load_episode, run_episode
    from tests.monitor.conftest import episode

    class Recording(Hub):
        def status(self, activity, detail="", **data):
            super().status(activity, detail, **data)
            seen.append((activity, detail))

    seen: list = []
    script = episode(tmp_path, steps=12)
    run_episode(load_episode(script), RunOptions(monitor=Recording(rate=50), plots=False,
                                                 camera="synthetic://?looking_at=centre"))
    assert [a for a, _ in seen] == ["starting", "waiting for the camera", "learning",
                                    "learning", "finished"]
    assert "camera synthetic://?looking_at=centre" in seen[1][1]
