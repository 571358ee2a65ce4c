"""The session live in Foxglove: the recording's channels over Foxglove's WebSocket protocol.

``relrl run EPISODE --foxglove [HOST:PORT]`` serves the channels of
:mod:`relrl.recording.channels` -- the camera with its annotations, the head's joint states,
percepts, working memory, necessities, reward, response and explanation, the tree, events --
to Foxglove (*Open connection* -> *Foxglove WebSocket*, ``ws://127.0.0.1:8765``) with the
``foxglove.websocket.v1`` subprotocol: the server sends ``serverInfo`` and ``advertise`` when
a client connects, and a binary message-data frame (opcode 1, subscription id, log time,
payload) for each message of a channel the client subscribed to. The newest message of each
channel is sent at once on subscribing, so a late client sees the tree and the last frame.

The rules of ``--monitor``: **read-only** (no capability is offered; a client's advertise,
publish, parameter or service request is answered with an error status and ignored);
**localhost by default** with the Host header checked; bound elsewhere, a token printed at
start is required (``?token=`` in the address or ``Authorization: Bearer``); **no web page
but the allowed**: a handshake with an ``Origin`` header (a browser sends one with every
WebSocket) is refused unless the user allowed that origin (``--foxglove-origin
https://app.foxglove.dev`` for Foxglove's web app), so a page open in the user's browser
cannot watch the session; a client that sends none (a program) is served; **at most**
:data:`MAX_CLIENTS` clients; and it **never stalls the session**: messages are handed over by
appending to a bounded deque; the server's own thread (asyncio, the
``websockets`` package) sends them, each client from a bounded queue of its own, so a slow
client loses old messages instead of holding anyone up. The server runs in the recording's
writer process (:mod:`relrl.recording.child`), not in the session's.
"""

from __future__ import annotations

import asyncio
import json
import secrets
import socket
import struct
import threading
import time
from collections import deque
from typing import Any

from relrl.monitor.server import check_origin, host_of, is_loopback, listen, parse_address
from relrl.recording.channels import CHANNELS, Channel

__all__ = ["FOXGLOVE_APP", "MAX_CLIENTS", "SUBPROTOCOL", "FoxgloveServer"]

SUBPROTOCOL = "foxglove.websocket.v1"
#: clients served at once; more are refused (503) until one leaves.
MAX_CLIENTS = 8
#: messages waiting to be sent, for the server and for each client (older ones are dropped).
BACKLOG = 1024
#: Foxglove's web app, the origin a user allows to watch in a browser.
FOXGLOVE_APP = "https://app.foxglove.dev"
#: seconds between two hand-overs from the session to the clients.
PERIOD = 0.02
_MESSAGE_DATA = 1


class _Client:
    def __init__(self, ws: Any) -> None:
        self.ws = ws
        self.subs: dict[int, int] = {}  # subscription id -> channel id
        self.by_channel: dict[int, int] = {}  # channel id -> subscription id
        self.queue: deque[bytes] = deque(maxlen=BACKLOG)
        self.wake = asyncio.Event()
        self.dropped = 0
        self.sender: Any = None


class FoxgloveServer:
    """A Foxglove WebSocket server in a daemon thread, fed encoded messages (it runs in the
    recording's writer process, :mod:`relrl.recording.child`).

    Args:
        address: ``HOST:PORT`` (default 127.0.0.1:8765; port 0: a free one).
        token: the token to require (default: a fresh one when not bound to loopback).
        channels: the channels to advertise.
        origins: the web origins whose pages may connect (checked with
            :func:`~relrl.monitor.server.parse_origin`); none by default.
    """

    def __init__(self, address: str | None = None, *, token: str | None = None,
                 channels: tuple[Channel, ...] = CHANNELS,
                 origins: tuple[str, ...] = ()) -> None:
        from relrl.monitor.server import parse_origin

        self.origins = frozenset(parse_origin(o) for o in origins)
        self.host, self.port = parse_address(address or "127.0.0.1:8765")
        self.loopback = is_loopback(self.host)
        self.token = token if token is not None else \
            (None if self.loopback else secrets.token_urlsafe(18))
        self.channels = {i: ch for i, ch in enumerate(channels, 1)}
        self._ids = {ch.topic: i for i, ch in self.channels.items()}
        self._inbox: deque[tuple[int, int, bytes]] = deque(maxlen=BACKLOG)
        self._latest: dict[int, tuple[int, bytes]] = {}
        self._clients: set[_Client] = set()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._stop: asyncio.Event | None = None
        self.sent = 0
        self.dropped = 0
        self.refused = 0

    @property
    def url(self) -> str:
        """The address to give Foxglove (with the token when one is needed)."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"ws://{host}:{self.port}" + (f"/?token={self.token}" if self.token else "")

    # -- the session's side (any thread; never waits) ---------------------------------------

    def write(self, channel: Channel, log_time: int, data: bytes) -> None:
        """Hand one encoded message over (dropped when the server is this far behind)."""
        cid = self._ids.get(channel.topic)
        if cid is not None:
            if len(self._inbox) == BACKLOG:
                self.dropped += 1  # the server thread is this far behind: the oldest goes
            self._inbox.append((cid, log_time, data))

    # -- start and stop -------------------------------------------------------------------

    def start(self) -> FoxgloveServer:
        """Bind and serve in the background.

        Raises:
            ConfigError: the address cannot be bound.
        """
        sock = listen(self.host, self.port, "Foxglove's server", MAX_CLIENTS)
        self.port = sock.getsockname()[1]
        ready = threading.Event()
        self._thread = threading.Thread(target=self._serve, args=(sock, ready),
                                        name="relrl-foxglove", daemon=True)
        self._thread.start()
        ready.wait(10)
        return self

    def close(self) -> None:
        """Stop serving (safe twice)."""
        loop, self._loop = self._loop, None
        if loop is not None and self._stop is not None:
            loop.call_soon_threadsafe(self._stop.set)
        if self._thread is not None:
            self._thread.join(timeout=5)
            self._thread = None

    def __enter__(self) -> FoxgloveServer:
        return self if self._thread is not None else self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the server's thread ---------------------------------------------------------------

    def _serve(self, sock: socket.socket, ready: threading.Event) -> None:
        asyncio.run(self._main(sock, ready))

    async def _main(self, sock: socket.socket, ready: threading.Event) -> None:
        from websockets.asyncio.server import serve

        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        async with serve(self._handle, sock=sock, subprotocols=[SUBPROTOCOL],
                         process_request=self._check, max_size=1 << 16, max_queue=16,
                         ping_interval=20, ping_timeout=20, close_timeout=1,
                         compression=None):
            ready.set()
            while not self._stop.is_set():
                self._fan_out()
                try:
                    await asyncio.wait_for(self._stop.wait(), PERIOD)
                except TimeoutError:
                    pass
            for client in list(self._clients):  # a client that stopped reading is cut off
                client.sender.cancel()
                try:
                    await asyncio.wait_for(client.ws.close(1001, "the session ended"), 1)
                except (TimeoutError, OSError):
                    client.ws.transport.abort()

    def _check(self, connection: Any, request: Any) -> Any:
        """Refuse a web page's origin not allowed, a wrong Host (loopback), a missing token
        (elsewhere), too many clients."""
        from urllib.parse import parse_qs, urlsplit

        origins = request.headers.get_all("Origin")
        why = check_origin(origins[0] if len(origins) == 1 else
                           (None if not origins else "(several)"), "", self.origins)
        if why is not None:
            self.refused += 1
            return connection.respond(403, f"{why}: the server serves the pages of the "
                                           "origins given with --foxglove-origin only\n")
        if self.token is not None:
            query = parse_qs(urlsplit(request.path).query)
            given = (query.get("token") or [""])[-1]
            auth = request.headers.get("Authorization", "")
            if auth.lower().startswith("bearer "):
                given = given or auth[7:].strip()
            if not secrets.compare_digest(given.encode(), self.token.encode()):
                self.refused += 1
                return connection.respond(401, "a token is required: use the address "
                                               "printed when the server started\n")
        else:
            hosts = request.headers.get_all("Host")
            host = host_of(hosts[0]) if len(hosts) == 1 else ""
            if host not in {"127.0.0.1", "localhost", "::1", self.host}:
                self.refused += 1
                return connection.respond(403, f"unexpected Host {host!r}\n")
        if len(self._clients) >= MAX_CLIENTS:
            self.refused += 1
            return connection.respond(503, f"at most {MAX_CLIENTS} clients at once\n")
        return None

    def _fan_out(self) -> None:
        """Move what the session handed over to the subscribed clients' queues."""
        inbox = self._inbox
        while inbox:
            cid, ns, data = inbox.popleft()
            self._latest[cid] = (ns, data)
            for client in self._clients:
                sub = client.by_channel.get(cid)
                if sub is not None:
                    if len(client.queue) == client.queue.maxlen:
                        client.dropped += 1
                    client.queue.append(_frame(sub, ns, data))
                    client.wake.set()

    def _advertise(self) -> str:
        chans = [{"id": i, "topic": ch.topic, "encoding": ch.encoding,
                  "schemaName": ch.schema, "schema": _schema_text(ch),
                  "schemaEncoding": ch.schema_encoding} for i, ch in self.channels.items()]
        return json.dumps({"op": "advertise", "channels": chans})

    async def _handle(self, ws: Any) -> None:
        client = _Client(ws)
        self._clients.add(client)
        client.sender = asyncio.create_task(self._send_loop(client))
        try:
            await ws.send(json.dumps({"op": "serverInfo", "name": "relrl", "capabilities": [],
                                      "supportedEncodings": [], "metadata": {},
                                      "sessionId": str(time.time_ns())}))
            await ws.send(self._advertise())
            async for raw in ws:
                await self._request(client, raw)
        except Exception:  # noqa: BLE001 - a client's fault ends its connection only
            pass
        finally:
            self._clients.discard(client)
            client.sender.cancel()

    async def _request(self, client: _Client, raw: Any) -> None:
        if isinstance(raw, bytes):
            await _status(client.ws, 2, "the server is read-only: no client data")
            return
        try:
            msg = json.loads(raw)
            op = msg["op"]
        except (ValueError, KeyError, TypeError):
            await _status(client.ws, 2, "not a JSON message with an op")
            return
        if op == "subscribe":
            for sub in msg.get("subscriptions") or []:
                sid, cid = sub.get("id"), sub.get("channelId")
                if not isinstance(sid, int) or cid not in self.channels or sid in client.subs:
                    await _status(client.ws, 2, f"bad subscription {sub!r}")
                    continue
                client.subs[sid] = cid
                client.by_channel[cid] = sid
                latest = self._latest.get(cid)
                if latest is not None:
                    client.queue.append(_frame(sid, *latest))
                    client.wake.set()
        elif op == "unsubscribe":
            for sid in msg.get("subscriptionIds") or []:
                cid = client.subs.pop(sid, None)
                if cid is not None:
                    client.by_channel.pop(cid, None)
        else:
            await _status(client.ws, 2, f"the server is read-only: {op!r} is not served")

    async def _send_loop(self, client: _Client) -> None:
        while True:
            await client.wake.wait()
            client.wake.clear()
            while client.queue:
                await client.ws.send(client.queue.popleft())
                self.sent += 1


def _schema_text(channel: Channel) -> str:
    """A channel's schema as the protocol carries it: text, or base64 for a binary one
    (protobuf's ``FileDescriptorSet``)."""
    if channel.encoding == "protobuf":
        import base64

        return base64.b64encode(channel.schema_data).decode()
    return channel.schema_data.decode()


def _frame(sub: int, ns: int, data: bytes) -> bytes:
    return struct.pack("<BIQ", _MESSAGE_DATA, sub, ns) + data


async def _status(ws: Any, level: int, message: str) -> None:
    await ws.send(json.dumps({"op": "status", "level": level, "message": message}))
