"""The live Foxglove server checked by a WebSocket client speaking Foxglove's protocol
(``foxglove.websocket.v1``: serverInfo, advertise, subscribe, binary message data) on
loopback; read-only, the token off loopback, bounded clients, never blocking the writer."""

from __future__ import annotations

import asyncio
import json
import struct
import time

import pytest
from websockets.asyncio.client import connect
from websockets.exceptions import InvalidStatus

from relrl.monitor.foxglove import FOXGLOVE_APP, MAX_CLIENTS, SUBPROTOCOL, FoxgloveServer
from relrl.recording.channels import CHANNELS, IMAGE, ROW_CHANNELS, TREE
from relrl.recording.encoder import Encoder


def _row(t: int) -> dict:
    return {"t": t, "phase": "p", "percepts": ["see(face)"], "memory": [], "memory_size": 0,
            "state": 1, "necessity": None, "activation": {"social": 0.5}, "reward": float(t),
            "response": "look(left)", "allowed": ["look(left)"], "explanation": None,
            "head": None, "metrics": {}, "overlay": None}


def _run(coro) -> object:
    """Run a client coroutine on an event loop of its own, in a thread (the test process may
    have a loop running in its main thread: Playwright's)."""
    import threading

    out: list = []

    def target() -> None:
        try:
            out.append(asyncio.run(coro))
        except BaseException as exc:  # noqa: BLE001 - raised again in the test
            out.append(exc)

    thread = threading.Thread(target=target)
    thread.start()
    thread.join(120)
    assert out, "the client never finished"
    if isinstance(out[0], BaseException):
        raise out[0]
    return out[0]


async def _hello(url: str) -> tuple[object, dict, dict]:
    ws = await connect(url, subprotocols=[SUBPROTOCOL], open_timeout=10)
    info = json.loads(await ws.recv())
    adv = json.loads(await ws.recv())
    return ws, info, adv


def test_advertise_subscribe_message() -> None:
    encoder = Encoder()
    with FoxgloveServer("127.0.0.1:0") as server:
        def send(messages: list) -> None:
            for message in messages:
                server.write(*message)

        send(encoder.tree(time.time_ns(), {"t": 0, "graph": {
            "nodes": [{"id": 0, "kind": "leaf", "label": "x"}], "edges": []}}))

        async def client() -> list:
            ws, info, adv = await _hello(f"ws://127.0.0.1:{server.port}")
            assert ws.subprotocol == SUBPROTOCOL
            assert info["op"] == "serverInfo" and info["capabilities"] == []
            assert adv["op"] == "advertise"
            by_topic = {c["topic"]: c for c in adv["channels"]}
            assert set(by_topic) == {c.topic for c in CHANNELS}
            assert by_topic[IMAGE.topic]["encoding"] == "cdr"
            assert by_topic[IMAGE.topic]["schemaEncoding"] == "ros2msg"
            assert "uint8[] data" in by_topic[IMAGE.topic]["schema"]
            reward = by_topic["/relrl/reward"]
            json.loads(reward["schema"])  # a JSON Schema
            await ws.send(json.dumps({"op": "subscribe", "subscriptions": [
                {"id": 7, "channelId": reward["id"]},
                {"id": 8, "channelId": by_topic[TREE.topic]["id"]}]}))
            got = []
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline and len([g for g in got if g[0] == 7]) < 5:
                await asyncio.sleep(0.05)
                send(encoder.unit(time.time_ns(), _row(len(got) + 1)))
                try:
                    raw = await asyncio.wait_for(ws.recv(), 0.5)
                except TimeoutError:
                    continue
                assert isinstance(raw, bytes) and raw[0] == 1
                sub, ns = struct.unpack_from("<IQ", raw, 1)
                got.append((sub, ns, json.loads(raw[13:])))
            await ws.close()
            return got

        got = _run(client())
    rewards = [m for s, _, m in got if s == 7]
    assert len(rewards) >= 5 and all(set(m) == {"t", "reward"} for m in rewards)
    trees = [m for s, _, m in got if s == 8]
    assert trees and trees[0]["graph"]["nodes"][0]["label"] == "x"  # sent on subscribing
    assert all(ns > 1_600_000_000 * 10**9 for _, ns, _ in got)  # the session's clock


def test_read_only_and_bad_requests_answered_with_status() -> None:
    with FoxgloveServer("127.0.0.1:0") as server:
        async def client() -> list:
            ws, _, _ = await _hello(f"ws://127.0.0.1:{server.port}")
            out = []
            for msg in ({"op": "advertise", "channels": [{"id": 1, "topic": "/cmd",
                                                         "encoding": "json",
                                                         "schemaName": "x"}]},
                        {"op": "setParameters", "parameters": []}, "not json",
                        {"op": "subscribe", "subscriptions": [{"id": 1, "channelId": 999}]}):
                await ws.send(msg if isinstance(msg, str) else json.dumps(msg))
                out.append(json.loads(await asyncio.wait_for(ws.recv(), 5)))
            await ws.send(b"\x01\x00\x00\x00\x01")  # client message data
            out.append(json.loads(await asyncio.wait_for(ws.recv(), 5)))
            await ws.close()
            return out

        answers = _run(client())
    assert all(a["op"] == "status" and a["level"] == 2 for a in answers)
    assert "read-only" in answers[0]["message"]


def _raw_upgrade(port: int, host: str, *origins: str) -> bytes:
    """A WebSocket upgrade request with a chosen Host header (DNS rebinding's) and Origin
    headers (a web page's)."""
    import socket

    extra = "".join(f"Origin: {o}\r\n" for o in origins)
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(f"GET / HTTP/1.1\r\nHost: {host}\r\n{extra}Upgrade: websocket\r\n"
                     "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                     f"Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: {SUBPROTOCOL}"
                     "\r\n\r\n".encode())
        return sock.recv(200)


def test_host_token_and_client_bound() -> None:
    with FoxgloveServer("127.0.0.1:0") as server:
        async def clients() -> None:
            assert _raw_upgrade(server.port, "evil.example:80").startswith(b"HTTP/1.1 403")
            assert _raw_upgrade(server.port, f"127.0.0.1:{server.port}").startswith(
                b"HTTP/1.1 101")
            held = [await _hello(f"ws://127.0.0.1:{server.port}") for _ in range(MAX_CLIENTS)]
            with pytest.raises(InvalidStatus) as err:
                await connect(f"ws://127.0.0.1:{server.port}", subprotocols=[SUBPROTOCOL],
                              open_timeout=5)
            assert err.value.response.status_code == 503
            for ws, _, _ in held:
                await ws.close()

        _run(clients())
    with FoxgloveServer("127.0.0.1:0", token="s3cret") as server:
        async def tokens() -> None:
            with pytest.raises(InvalidStatus) as err:
                await connect(f"ws://127.0.0.1:{server.port}", open_timeout=5)
            assert err.value.response.status_code == 401
            ws, info, _ = await _hello(f"ws://127.0.0.1:{server.port}/?token=s3cret")
            assert info["op"] == "serverInfo"
            await ws.close()

        _run(tokens())


def test_a_web_pages_origin_is_refused_unless_allowed() -> None:
    """A page open in the user's browser (any site) cannot watch the session: a handshake
    with an Origin is refused unless that origin was allowed; programs send none."""
    with FoxgloveServer("127.0.0.1:0") as server:
        here = f"127.0.0.1:{server.port}"
        for origin in ("https://evil.example.com", "null", f"http://{here}",
                       "https://app.foxglove.dev"):
            assert _raw_upgrade(server.port, here, origin).startswith(b"HTTP/1.1 403"), origin
        assert _raw_upgrade(server.port, here).startswith(b"HTTP/1.1 101")  # a program
    with FoxgloveServer("127.0.0.1:0", origins=(FOXGLOVE_APP,)) as server:
        here = f"127.0.0.1:{server.port}"
        assert _raw_upgrade(server.port, here, "https://app.foxglove.dev").startswith(
            b"HTTP/1.1 101")
        assert _raw_upgrade(server.port, here, "HTTPS://APP.FOXGLOVE.DEV").startswith(
            b"HTTP/1.1 101")
        for origins in (("https://evil.example.com",), ("https://app.foxglove.dev.evil.com",),
                        ("https://app.foxglove.dev", "https://evil.example.com")):
            assert _raw_upgrade(server.port, here, *origins).startswith(b"HTTP/1.1 403")
    with FoxgloveServer("127.0.0.1:0", token="s3cret") as server:  # a token is not an origin
        assert _raw_upgrade(server.port, f"127.0.0.1:{server.port}",
                            "https://evil.example.com").startswith(b"HTTP/1.1 403")


@pytest.mark.parametrize("origin", ["*", "null", "https://app.foxglove.dev/", "app.foxglove.dev",
                                    "ftp://x.org", "https://a.org/path", "https://u@a.org",
                                    "https://a.org:99999", "https://a.org:x"])
def test_a_bad_allowed_origin_is_one_line(origin: str) -> None:
    from relrl.errors import ConfigError

    with pytest.raises(ConfigError, match="bad origin"):
        FoxgloveServer("127.0.0.1:0", origins=(origin,))


@pytest.mark.slow
def test_a_stalled_client_never_holds_the_writer() -> None:
    """A client that subscribes to everything and never reads: the session's writes stay
    fast (an append) and the server drops what the client cannot take."""
    with FoxgloveServer("127.0.0.1:0") as server:
        async def stalled() -> object:
            ws, _, adv = await _hello(f"ws://127.0.0.1:{server.port}")
            await ws.send(json.dumps({"op": "subscribe", "subscriptions": [
                {"id": c["id"], "channelId": c["id"]} for c in adv["channels"]]}))
            return ws

        loop = asyncio.new_event_loop()
        import threading

        held: list = []  # the connection, made on a loop that then stops running
        connect_thread = threading.Thread(
            target=lambda: held.append(loop.run_until_complete(stalled())))
        connect_thread.start()
        connect_thread.join(30)
        assert held
        big = b"x" * 200_000
        took = 0.0
        for i in range(3000):
            t0 = time.perf_counter()
            server.write(IMAGE, i, big)
            server.write(ROW_CHANNELS[3], i, b'{"t":1,"reward":0}')
            took = max(took, time.perf_counter() - t0)
            if i % 300 == 0:
                time.sleep(0.05)  # the server's thread hands them over meanwhile
        time.sleep(0.5)
        assert took < 0.05  # no write ever waited for the client
        client = next(iter(server._clients))
        assert client.dropped > 0  # the server dropped what the client could not take
        t0 = time.perf_counter()
        server.close()  # the client still stalled: it is cut off, not waited for
        assert time.perf_counter() - t0 < 3
    def clean() -> None:
        tasks = asyncio.all_tasks(loop)
        for task in tasks:
            task.cancel()
        loop.run_until_complete(asyncio.gather(*tasks, return_exceptions=True))
        loop.close()

    cleaner = threading.Thread(target=clean)
    cleaner.start()
    cleaner.join(30)


def test_bad_address_is_one_line() -> None:
    from relrl.errors import ConfigError

    with pytest.raises(ConfigError, match="port must be a number"):
        FoxgloveServer("127.0.0.1:99999")


@pytest.mark.slow
def test_a_live_session_in_foxglove(tmp_path) -> None:
    """relrl run --foxglove: a client subscribes to the camera, its annotations, the
    percepts and the joint states, and decodes each with the advertised schema."""
    import base64
    import subprocess
    import sys
    from pathlib import Path

    from mcap.records import Schema
    from mcap_ros2.decoder import DecoderFactory

    from tests.conftest import ROOT
    from tests.monitor.conftest import episode
    from tests.recording.foxglove_proto import protobuf_decoder

    script = episode(tmp_path, steps=400)
    proc = subprocess.Popen([sys.executable, "-m", "relrl", "-q", "run", str(script),
                             "--head", "sim", "--foxglove", "127.0.0.1:0",
                             "--foxglove-origin", "https://app.foxglove.dev", "--step-seconds",
                             "0.02", "--no-plots"], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        url = None
        for line in proc.stdout:
            if line.startswith("foxglove: "):
                url = line.split()[1]
                break
        assert url and url.startswith("ws://127.0.0.1:")
        here = url.split("//")[1].rstrip("/")
        port = int(here.split(":")[1])
        # the origin allowed on the command line reaches the server; no other page does
        assert _raw_upgrade(port, here, "https://app.foxglove.dev").startswith(b"HTTP/1.1 101")
        assert _raw_upgrade(port, here, "https://evil.example.com").startswith(b"HTTP/1.1 403")

        async def client() -> dict:
            ws, _, adv = await _hello(url)
            chans = {c["topic"]: c for c in adv["channels"]}
            wanted = ["/camera/image/compressed", "/camera/annotations", "/relrl/percepts",
                      "/head/joint_states", "/tf", "/head/scene"]
            await ws.send(json.dumps({"op": "subscribe", "subscriptions": [
                {"id": i, "channelId": chans[t]["id"]} for i, t in enumerate(wanted)]}))
            got: dict[str, list] = {}
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline and len(got) < len(wanted):
                raw = await asyncio.wait_for(ws.recv(), 30)
                if isinstance(raw, bytes):
                    sub, ns = struct.unpack_from("<IQ", raw, 1)
                    topic = wanted[sub]
                    ch = chans[topic]
                    if ch["encoding"] == "protobuf":  # the schema in base64
                        schema = Schema(id=ch["id"], name=ch["schemaName"], encoding="protobuf",
                                        data=base64.b64decode(ch["schema"]))
                        msg = protobuf_decoder(schema)(raw[13:])
                    elif ch["encoding"] == "cdr":
                        schema = Schema(id=ch["id"], name=ch["schemaName"], encoding="ros2msg",
                                        data=ch["schema"].encode())
                        msg = DecoderFactory().decoder_for("cdr", schema)(raw[13:])
                    else:
                        msg = json.loads(raw[13:])
                    got.setdefault(topic, []).append(msg)
            await ws.close()
            return got

        got = _run(client())
    finally:
        proc.kill()
        proc.wait(30)
    assert set(got) == {"/camera/image/compressed", "/camera/annotations", "/relrl/percepts",
                        "/head/joint_states", "/tf", "/head/scene"}
    assert {tf.child_frame_id for tf in got["/tf"][0].transforms} >= {"neck_pan_link", "camera"}
    assert "gaze" in {e.id for e in got["/head/scene"][0].entities}
    assert got["/camera/image/compressed"][0].format == "jpeg"
    assert bytes(got["/camera/image/compressed"][0].data[:2]) == b"\xff\xd8"  # a JPEG
    assert "percepts" in got["/relrl/percepts"][0]
    assert len(got["/head/joint_states"][0].name) >= 2
    assert not Path(tmp_path / "session.mcap").exists()  # live only: nothing written


@pytest.mark.parametrize("argv, needle", [
    (["--foxglove", "--foxglove-origin", "https://*.evil.example"], "*.evil.example"),
    (["--foxglove", "--foxglove-origin", "null"], "null"),
    (["--foxglove-origin", "https://app.foxglove.dev"], "needs --foxglove"),
])
def test_a_bad_foxglove_origin_flag_is_one_line(tmp_path, capsys, argv: list[str],
                                                needle: str) -> None:
    from tests.cli.conftest import one_line_exit_2
    from tests.monitor.conftest import episode

    one_line_exit_2(capsys, ["run", str(episode(tmp_path, steps=40)), "--no-plots", *argv],
                    needle)
