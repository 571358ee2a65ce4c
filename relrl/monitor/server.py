"""The monitor's web server: Starlette + uvicorn in a thread, server-sent events, read-only.

One page (``static/index.html``, plain JavaScript, no build step) serves both the live
session and a replay. Live: ``/api/events`` streams the newest view as server-sent events at
the hub's rate, ``/frame.jpg`` is the newest camera frame, ``/tree.svg`` the learner's tree.
Replay: ``/api/step/{t}``, ``/api/series``, ``/frames/{i}.jpg`` and ``/tree.svg?t=``.

Read-only by construction: every route answers GET (and HEAD) only, anything else is 405,
and no handler touches the robot or the knowledge base (they read the hub or the recording).
Bound to a loopback address, the server checks the Host header (no DNS rebinding); bound
elsewhere, every request must carry the token printed at start (``?token=``, a
``Authorization: Bearer`` header, or the cookie the page sets).
"""

from __future__ import annotations

import asyncio
import ipaddress
import json
import secrets
import socket
import threading
from pathlib import Path
from typing import Any

from relrl.errors import ConfigError

__all__ = ["MonitorServer", "build_app", "is_loopback", "listen", "parse_address"]

STATIC = Path(__file__).resolve().parent / "static"
DEFAULT_HOST = "127.0.0.1"
_READ_METHODS = frozenset({"GET", "HEAD"})


def parse_address(text: str | None) -> tuple[str, int]:
    """``HOST:PORT``, ``:PORT``, ``PORT`` or ``HOST`` (port 0: a free one); default
    127.0.0.1 with a free port.

    Raises:
        ConfigError: a port that is not a number in 0..65535.
    """
    if not text:
        return DEFAULT_HOST, 0
    host, port = DEFAULT_HOST, "0"
    if text.startswith("[") and "]" in text:  # [::1]:8000
        host, _, rest = text[1:].partition("]")
        port = rest.lstrip(":") or "0"
    elif text.count(":") == 1:
        host, port = text.split(":")
        host = host or DEFAULT_HOST
    elif text.isdigit():
        port = text
    else:
        host = text
    if not port.isdigit() or not 0 <= int(port) <= 65535:
        raise ConfigError(f"bad monitor address {text!r}: the port must be a number in "
                          "0..65535 (use HOST:PORT, e.g. 127.0.0.1:8765)")
    return host, int(port)


def listen(host: str, port: int, what: str, backlog: int) -> socket.socket:
    """A TCP socket bound to ``host:port`` and listening (port 0: a free one).

    Raises:
        ConfigError: the address cannot be bound (in use, not on this machine), naming
            ``what`` would have listened there.
    """
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
    except (OSError, OverflowError) as exc:
        sock.close()
        raise ConfigError(f"{what} cannot listen on {host}:{port}: "
                          f"{getattr(exc, 'strerror', None) or exc}") from None
    sock.listen(backlog)
    return sock


def is_loopback(host: str) -> bool:
    """Whether ``host`` is a loopback address (or ``localhost``)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _json(data: Any, status: int = 200) -> Any:
    from starlette.responses import Response

    return Response(json.dumps(data, allow_nan=False, default=str), status_code=status,
                    media_type="application/json", headers={"Cache-Control": "no-store"})


class _Guard:
    """ASGI middleware: GET/HEAD only, the token off loopback, the Host header on loopback."""

    def __init__(self, app: Any, token: str | None, hosts: set[str]) -> None:
        self.app, self.token, self.hosts = app, token, hosts

    def _token_of(self, scope: dict[str, Any]) -> str | None:
        from urllib.parse import parse_qs

        query = parse_qs(scope.get("query_string", b"").decode("latin-1"))
        if query.get("token"):
            return query["token"][-1]
        headers = {k.decode("latin-1").lower(): v.decode("latin-1")
                   for k, v in scope.get("headers", [])}
        auth = headers.get("authorization", "")
        if auth.lower().startswith("bearer "):
            return auth[7:].strip()
        for part in headers.get("cookie", "").split(";"):
            name, _, value = part.strip().partition("=")
            if name == "relrl_token":
                return value
        return None

    async def __call__(self, scope: dict[str, Any], receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        from starlette.responses import PlainTextResponse

        if scope["method"] not in _READ_METHODS:
            response = PlainTextResponse("the monitor is read-only\n", status_code=405,
                                         headers={"Allow": "GET, HEAD"})
        elif self.token is not None:
            given = self._token_of(scope) or ""
            if secrets.compare_digest(given.encode(), self.token.encode()):
                await self.app(scope, receive, send)
                return
            response = PlainTextResponse("a token is required: use the address printed "
                                         "when the monitor started\n", status_code=401)
        else:
            headers = dict(scope.get("headers", []))
            host = headers.get(b"host", b"").decode("latin-1").rsplit(":", 1)[0].strip("[]")
            if host in self.hosts:
                await self.app(scope, receive, send)
                return
            response = PlainTextResponse(f"unexpected Host {host!r}\n", status_code=403)
        await response(scope, receive, send)


def build_app(source: Any, *, token: str | None = None, hosts: set[str] | None = None) -> Any:
    """The Starlette application over a live :class:`LiveSource` or a replay source.

    Args:
        source: what the page shows (``source.mode`` is ``"live"`` or ``"replay"``).
        token: required on every request when given.
        hosts: Host header values accepted without a token (loopback names).
    """
    from starlette.applications import Starlette
    from starlette.responses import FileResponse, Response, StreamingResponse
    from starlette.routing import Mount, Route
    from starlette.staticfiles import StaticFiles

    async def index(request: Any) -> Any:
        response = FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-store"})
        if token is not None and request.query_params.get("token") == token:
            response.set_cookie("relrl_token", token, httponly=True, samesite="strict")
        return response

    async def info(request: Any) -> Any:
        return _json({"mode": source.mode, **source.info()})

    async def events(request: Any) -> Any:
        async def stream() -> Any:
            version, count = -1, 0
            yield "retry: 1000\n\n"
            while True:
                msg, version, count = source.message(version, count)
                if msg is not None:
                    yield f"data: {json.dumps(msg, allow_nan=False, default=str)}\n\n"
                    if msg.get("finished"):
                        return
                await asyncio.sleep(source.period)

        return StreamingResponse(stream(), media_type="text/event-stream",
                                 headers={"Cache-Control": "no-store",
                                          "X-Accel-Buffering": "no"})

    def _jpeg(data: bytes | None) -> Any:
        if data is None:
            return Response("no frame\n", status_code=404, media_type="text/plain")
        return Response(data, media_type="image/jpeg", headers={"Cache-Control": "no-store"})

    async def frame(request: Any) -> Any:
        got = source.jpeg()  # about a millisecond for a 320x240 frame, once per frame
        return _jpeg(None if got is None else got[1])

    async def recorded_frame(request: Any) -> Any:
        return _jpeg(source.frame_jpeg(int(request.path_params["index"])))

    async def tree(request: Any) -> Any:
        t = request.query_params.get("t")
        svg = await asyncio.to_thread(source.tree_svg, int(t) if t and t.isdigit() else None)
        if svg is None:
            return Response("no tree\n", status_code=404, media_type="text/plain")
        return Response(svg, media_type="image/svg+xml", headers={"Cache-Control": "no-store"})

    async def step(request: Any) -> Any:
        row = source.step(int(request.path_params["t"]))
        return _json(row) if row is not None else _json({"error": "no such time unit"}, 404)

    async def series(request: Any) -> Any:
        return _json(source.series())

    async def no_icon(request: Any) -> Any:
        return Response(status_code=204)

    routes = [Route("/", index), Route("/api/info", info), Route("/tree.svg", tree),
              Route("/favicon.ico", no_icon),
              Mount("/static", StaticFiles(directory=STATIC))]
    if source.mode == "live":
        routes += [Route("/api/events", events), Route("/frame.jpg", frame)]
    else:
        routes += [Route("/api/step/{t:int}", step), Route("/api/series", series),
                   Route("/frames/{index:int}.jpg", recorded_frame)]
    app = Starlette(routes=routes)
    return _Guard(app, token, hosts or {"127.0.0.1", "localhost", "::1"})


class LiveSource:
    """The live session as the server reads it (a :class:`~relrl.monitor.hub.Hub`)."""

    mode = "live"

    def __init__(self, hub: Any) -> None:
        self.hub = hub
        self.period = hub.period
        self._svg: tuple[int, bytes | None] = (-1, None)
        self._svg_lock = threading.Lock()

    def info(self) -> dict[str, Any]:
        return {"rate": self.hub.rate, **self.hub.info}

    def message(self, version: int, count: int) -> tuple[dict[str, Any] | None, int, int]:
        return self.hub.message(version, count)

    def jpeg(self) -> tuple[int, bytes] | None:
        return self.hub.jpeg()

    def tree_svg(self, t: int | None = None) -> bytes | None:
        from relrl.monitor.graph import render

        with self._svg_lock:
            version, graph = self.hub.tree_version, self.hub.tree
            if self._svg[0] != version:
                self._svg = (version, render(graph) if graph and graph.get("nodes") else None)
            return self._svg[1]


class MonitorServer:
    """The web server in a daemon thread; ``start()`` binds (errors are one line), ``close()``
    stops it (safe twice).

    Args:
        source: a :class:`LiveSource` or a replay source.
        address: ``HOST:PORT`` (see :func:`parse_address`).
        token: the token to require (default: a fresh one when not bound to loopback).
    """

    def __init__(self, source: Any, address: str | None = None, *,
                 token: str | None = None) -> None:
        self.source = source
        self.host, self.port = parse_address(address)
        self.loopback = is_loopback(self.host)
        self.token = token if token is not None else \
            (None if self.loopback else secrets.token_urlsafe(18))
        self._server: Any = None
        self._thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        """The page's address (with the token when one is needed)."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        query = f"?token={self.token}" if self.token else ""
        return f"http://{host}:{self.port}/{query}"

    def start(self) -> MonitorServer:
        """Bind and serve in the background.

        Raises:
            ConfigError: the address cannot be bound (in use, not on this machine).
        """
        import uvicorn

        sock = listen(self.host, self.port, "the monitor", 16)
        self.port = sock.getsockname()[1]
        hosts = {"127.0.0.1", "localhost", "::1", self.host}
        app = build_app(self.source, token=self.token, hosts=hosts)
        config = uvicorn.Config(app, log_level="warning", access_log=False, lifespan="off",
                                timeout_graceful_shutdown=1)
        self._server = uvicorn.Server(config)
        self._thread = threading.Thread(target=self._server.run, kwargs={"sockets": [sock]},
                                        name="relrl-monitor", daemon=True)
        self._thread.start()
        self._sock = sock
        return self

    def close(self) -> None:
        """Stop serving (safe twice)."""
        if self._server is not None:
            self._server.should_exit = True
            self._server.force_exit = True
            if self._thread is not None:
                self._thread.join(timeout=5)
            self._sock.close()
            self._server = None

    def __enter__(self) -> MonitorServer:
        return self if self._server is not None else self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()
