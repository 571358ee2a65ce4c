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

PATHS = ["/", "/api/info", "/api/events", "/frame.jpg", "/tree.svg", "/static/monitor.js"]


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
