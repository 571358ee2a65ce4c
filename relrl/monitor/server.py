"""The monitor's web server: Starlette + uvicorn in a thread, server-sent events, read-only.

One page (``static/index.html``, plain JavaScript, no build step) serves both the live
session and a replay. Live: ``/api/events`` streams the newest view as server-sent events at
the hub's rate, ``/frame.jpg`` is the newest camera frame, ``/tree.svg`` the learner's tree
and ``/api/tree`` the same picture with what the page marks the current leaf and its path
with (the nodes' names and parents) and the legend of the learner's leaves.
Replay: ``/api/step/{t}``, ``/api/series``, ``/frames/{i}.jpg``, ``/tree.svg?t=`` and
``/api/tree?t=``.

Read-only by construction: every route answers GET (and HEAD) only, anything else is 405,
and no handler touches the robot or the knowledge base (they read the hub or the recording).
Bound to a loopback address, the server checks the Host header (no DNS rebinding); bound
elsewhere, every request must carry the token printed at start (``?token=``, a
``Authorization: Bearer`` header, or the cookie the page sets). Either way a request another
web site's page makes is refused (403): an ``Origin`` header other than the monitor's own
(:func:`same_origin`), or a browser's ``Sec-Fetch-Site: cross-site`` on anything but the
user opening a page (``Sec-Fetch-Mode: navigate``); so a page open in the user's browser can
neither read the session nor embed its frames. Only HTTP is served: a WebSocket is refused.

Hostile clients: connections, request time and send time are bounded
(:mod:`relrl.monitor.bounds`); numbers in paths and queries are ASCII digits, at most 15 of
them; every answer carries a content-security policy (the tree's SVG one that runs nothing)
and ``nosniff``; JSON never holds NaN (it becomes ``null``); a handler that fails anyway
answers 500 and logs one line, never a traceback. The live session's server runs in a
process of its own (:mod:`relrl.monitor.live`); replay's in a thread.
"""

from __future__ import annotations

import asyncio
import ipaddress
import json
import logging
import re
import secrets
import socket
import threading
from abc import ABC, abstractmethod
from pathlib import Path
from typing import Any

from relrl.errors import ConfigError
from relrl.monitor.bounds import Limits, bounded_protocol
from relrl.monitor.graph import LEAF_LEGENDS, Picture
from relrl.monitor.schema import finite

__all__ = ["Endpoint", "LiveSource", "MonitorServer", "build_app", "check_origin", "host_of",
           "is_loopback", "listen", "parse_address", "parse_origin", "same_origin", "whole"]

log = logging.getLogger(__name__)

STATIC = Path(__file__).resolve().parent / "static"
DEFAULT_HOST = "127.0.0.1"
_READ_METHODS = frozenset({"GET", "HEAD"})
#: the page: its own scripts, styles and pictures, nothing inline, never framed.
PAGE_CSP = ("default-src 'none'; script-src 'self'; style-src 'self'; "
            "img-src 'self' data: blob:; connect-src 'self'; base-uri 'none'; "
            "form-action 'none'; frame-ancestors 'none'")
#: the tree's SVG, even opened on its own: no script, no link target, a sandbox.
PICTURE_CSP = "default-src 'none'; style-src 'unsafe-inline'; img-src data:; sandbox"
_SECURITY = [(b"x-content-type-options", b"nosniff"), (b"referrer-policy", b"no-referrer"),
             (b"cross-origin-resource-policy", b"same-origin")]
_WHOLE = re.compile(r"-?[0-9]{1,15}")
#: client connections waiting to be accepted (the kernel holds them, not this process), and
#: the most accepted in one go (asyncio takes up to this many before the cap is applied).
BACKLOG = 64


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


def is_loopback(host: str) -> bool:
    """Whether ``host`` is a loopback address (or ``localhost``)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def host_of(header: str) -> str:
    """The host of a ``Host`` header, lower-case, without its port or IPv6 brackets
    (``[::1]:8000`` and ``[::1]`` are ``::1``; ``localhost:80`` is ``localhost``)."""
    value = header.strip().lower()
    if value.startswith("["):
        inside, bracket, _ = value[1:].partition("]")
        return inside if bracket else ""
    if value.count(":") == 1:
        return value.split(":")[0]
    return value  # a name, an IPv4 address, or an IPv6 address given without brackets


def same_origin(origin: str, host: str) -> bool:
    """Whether a request's ``Origin`` header names the server it was sent to: ``http://``
    (or ``https://``, behind a proxy that adds TLS) and the request's ``Host`` header, letter
    for letter (case aside)."""
    value, host = origin.strip().lower(), host.strip().lower()
    return bool(host) and value in ("http://" + host, "https://" + host)


def check_origin(origin: str | None, host: str, allowed: frozenset[str] = frozenset()
                 ) -> str | None:
    """Why a request with this ``Origin`` header is refused, or ``None`` when it is served.

    Browsers send ``Origin`` with every WebSocket handshake and every cross-origin request,
    so a request without one comes from a program, not from a web page; one with it is
    served when it is the server's own origin (:func:`same_origin`) or one of ``allowed``.

    Args:
        origin: the ``Origin`` header (``None``: none was sent).
        host: the request's ``Host`` header.
        allowed: origins the user allowed (``https://app.foxglove.dev``), lower-case.
    """
    if origin is None or same_origin(origin, host) or origin.strip().lower() in allowed:
        return None
    return f"a request from the web page origin {origin[:100]!r} is refused"


def parse_origin(text: str) -> str:
    """An origin a user allows, checked and in lower case: ``SCHEME://HOST[:PORT]`` with
    ``http`` or ``https`` and nothing after (``https://app.foxglove.dev``).

    Raises:
        ConfigError: anything else (a path, a wildcard, ``null``).
    """
    from urllib.parse import urlsplit

    value = text.strip().lower()
    try:
        parts = urlsplit(value)
        ok = (parts.port is None or parts.port > 0) and parts.scheme in ("http", "https") \
            and bool(parts.hostname) and value == f"{parts.scheme}://{parts.netloc}" \
            and "@" not in value and "*" not in value
    except ValueError:  # a port that is not a number
        ok = False
    if not ok:
        raise ConfigError(f"bad origin {text[:100]!r}: give SCHEME://HOST[:PORT] as a browser "
                          "sends it, e.g. https://app.foxglove.dev")
    return value


def whole(text: str | None) -> int | None:
    """``text`` as an integer when it is ASCII digits (at most 15, an optional minus), else
    ``None`` (no ``'²'``, no 5,000-digit numbers)."""
    if text is None or not _WHOLE.fullmatch(text):
        return None
    return int(text)


def _dumps(data: Any) -> str:
    try:
        return json.dumps(data, allow_nan=False, default=str)
    except ValueError:  # a NaN somewhere: said as null
        return json.dumps(finite(data), allow_nan=False, default=str)


def _json(data: Any, status: int = 200) -> Any:
    from starlette.responses import Response

    return Response(_dumps(data), status_code=status, media_type="application/json",
                    headers={"Cache-Control": "no-store"})


def _text(message: str, status: int) -> Any:
    from starlette.responses import Response

    return Response(message + "\n", status_code=status, media_type="text/plain",
                    headers={"Cache-Control": "no-store"})


class _Guard:
    """ASGI middleware: GET/HEAD only, the token off loopback, the Host header on loopback."""

    def __init__(self, app: Any, token: str | None, hosts: set[str]) -> None:
        self.app, self.token = app, token
        self.hosts = {host_of(h) if h.startswith("[") else h.lower() for h in hosts}

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
        if scope["type"] == "websocket":  # the monitor serves HTTP only
            await send({"type": "websocket.close", "code": 1008})
            return
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        from starlette.responses import PlainTextResponse

        started = False

        async def secured(message: dict[str, Any]) -> None:
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
                headers = list(message.get("headers", []))
                kind = dict(headers).get(b"content-type", b"")
                csp = PICTURE_CSP if kind.startswith(b"image/svg") else PAGE_CSP
                message = {**message, "headers": headers + _SECURITY + [
                    (b"content-security-policy", csp.encode())]}
            await send(message)

        headers = {k.decode("latin-1").lower(): v.decode("latin-1")
                   for k, v in scope.get("headers", [])}
        refused = _cross_site(headers)
        if scope["method"] not in _READ_METHODS:
            response = PlainTextResponse("the monitor is read-only\n", status_code=405,
                                         headers={"Allow": "GET, HEAD"})
        elif refused is not None:
            response = PlainTextResponse(refused + "\n", status_code=403)
        elif self.token is not None:
            given = self._token_of(scope) or ""
            if secrets.compare_digest(given.encode(), self.token.encode()):
                await self._answer(scope, receive, secured, lambda: started)
                return
            response = PlainTextResponse("a token is required: use the address printed "
                                         "when the monitor started\n", status_code=401)
        else:
            host = host_of(headers.get("host", ""))
            if host in self.hosts:
                await self._answer(scope, receive, secured, lambda: started)
                return
            response = PlainTextResponse(f"unexpected Host {host!r}\n", status_code=403)
        await response(scope, receive, secured)

    async def _answer(self, scope: dict[str, Any], receive: Any, send: Any,
                      started: Any) -> None:
        """The application's answer; one that fails is a 500 and one log line."""
        try:
            await self.app(scope, receive, send)
        except Exception as exc:  # a bug: said in one line, the server goes on
            log.warning("the monitor could not answer %s: %s: %s", scope.get("path"),
                        type(exc).__name__, str(exc)[:200])
            if not started():
                await _text("the monitor could not answer this request", 500)(
                    scope, receive, send)


def _cross_site(headers: dict[str, str]) -> str | None:
    """Why a request another site's page made is refused, or ``None``: an ``Origin`` that is
    not the monitor's, or ``Sec-Fetch-Site: cross-site`` on anything but opening a page."""
    why = check_origin(headers.get("origin"), headers.get("host", ""))
    if why is not None:
        return why
    if headers.get("sec-fetch-site") == "cross-site" \
            and headers.get("sec-fetch-mode") != "navigate":
        return "a request another web site's page makes is refused"
    return None


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
                    yield f"data: {_dumps(msg)}\n\n"
                    if msg.get("finished"):
                        return
                await asyncio.sleep(source.period)

        return StreamingResponse(stream(), media_type="text/event-stream",
                                 headers={"Cache-Control": "no-store",
                                          "X-Accel-Buffering": "no"})

    def _jpeg(data: bytes | None) -> Any:
        if data is None:
            return _text("no frame", 404)
        return Response(data, media_type="image/jpeg", headers={"Cache-Control": "no-store"})

    async def frame(request: Any) -> Any:
        got = source.jpeg()  # encoded once per frame, by whoever feeds the hub
        return _jpeg(None if got is None else got[1])

    async def recorded_frame(request: Any) -> Any:
        index = whole(request.path_params["index"])
        if index is None:
            return _text("no frame (frames are /frames/N.jpg, N from 1)", 404)
        return _jpeg(await asyncio.to_thread(source.frame_jpeg, index))

    async def drawing(request: Any) -> Any:
        """The tree's picture at ``?t=`` (replay; live: the newest), or the answer saying
        why there is none."""
        from relrl.monitor.graph import GraphError

        text = request.query_params.get("t")
        t = whole(text)
        if text is not None and t is None:
            return _text(f"t must be a time unit (a whole number), not {text[:40]!r}", 400)
        try:
            drawn = await asyncio.to_thread(source.tree_picture, t)
        except GraphError as exc:
            return _text(f"the tree cannot be drawn: {exc}", 422)
        return drawn if drawn is not None else _text("no tree", 404)

    async def tree(request: Any) -> Any:
        drawn = await drawing(request)
        if not isinstance(drawn, Picture):
            return drawn
        return Response(drawn.svg, media_type="image/svg+xml",
                        headers={"Cache-Control": "no-store"})

    async def tree_json(request: Any) -> Any:
        drawn = await drawing(request)
        if not isinstance(drawn, Picture):
            return drawn
        return _json({"svg": drawn.svg.decode("utf-8", "replace"), "names": drawn.names,
                      "parents": drawn.parents,
                      "legend": LEAF_LEGENDS.get(str(source.info().get("learner")), [])})

    async def step(request: Any) -> Any:
        t = whole(request.path_params["t"])
        row = None if t is None else source.step(t)
        return _json(row) if row is not None else _json({"error": "no such time unit"}, 404)

    async def series(request: Any) -> Any:
        return _json(source.series())

    async def no_icon(request: Any) -> Any:
        return Response(status_code=204)

    routes = [Route("/", index), Route("/api/info", info), Route("/tree.svg", tree),
              Route("/api/tree", tree_json),
              Route("/favicon.ico", no_icon),
              Mount("/static", StaticFiles(directory=STATIC))]
    if source.mode == "live":
        routes += [Route("/api/events", events), Route("/frame.jpg", frame)]
    else:
        routes += [Route("/api/step/{t}", step), Route("/api/series", series),
                   Route("/frames/{index}.jpg", recorded_frame)]
    app = Starlette(routes=routes)
    return _Guard(app, token, hosts or {"127.0.0.1", "localhost", "::1"})


def drawn(graph: dict[str, Any] | None) -> Picture | Exception | None:
    """The tree's :class:`~relrl.monitor.graph.Picture`, the
    :class:`~relrl.monitor.graph.GraphError` saying why it cannot be drawn (kept, so a tree
    that fails is not drawn again), or ``None`` for no tree."""
    from relrl.monitor.graph import GraphError, picture

    if not graph or not graph.get("nodes"):
        return None
    try:
        return picture(graph)
    except GraphError as exc:
        log.warning("the tree cannot be drawn: %s", exc)
        return exc


class LiveSource:
    """The live session as the server reads it (a :class:`~relrl.monitor.hub.Hub`)."""

    mode = "live"

    def __init__(self, hub: Any) -> None:
        self.hub = hub
        self.period = hub.period
        self._svg: tuple[int, Picture | Exception | None] = (-1, None)
        self._svg_lock = threading.Lock()

    def info(self) -> dict[str, Any]:
        return {"rate": self.hub.rate, **self.hub.info}

    def message(self, version: int, count: int) -> tuple[dict[str, Any] | None, int, int]:
        return self.hub.message(version, count)

    def jpeg(self) -> tuple[int, bytes] | None:
        return self.hub.jpeg()

    def tree_picture(self, t: int | None = None) -> Picture | None:
        """The newest tree drawn (``t`` is for replay; live shows the newest).

        Raises:
            GraphError: the tree cannot be drawn.
        """
        with self._svg_lock:
            version, graph = self.hub.tree_state()
            if self._svg[0] != version:
                self._svg = (version, drawn(graph))
            svg = self._svg[1]
        if isinstance(svg, Exception):
            raise svg
        return svg


def listen(host: str, port: int, what: str = "the monitor",
           backlog: int | None = None) -> socket.socket:
    """A TCP socket listening on ``host:port`` (port 0: a free one).

    Args:
        host, port: the address.
        what: who would listen there, for the message.
        backlog: connections the kernel may hold before they are accepted (default
            :data:`BACKLOG`).

    Raises:
        ConfigError: the address cannot be bound (in use, not on this machine).
    """
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    # IPPROTO_TCP named, so that the connections it accepts get TCP_NODELAY from asyncio
    # (without it a keep-alive answer waits 40 ms for the client's delayed ACK)
    sock = socket.socket(family, socket.SOCK_STREAM, socket.IPPROTO_TCP)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((host, port))
        sock.listen(BACKLOG if backlog is None else backlog)
    except (OSError, OverflowError) as exc:
        sock.close()
        raise ConfigError(f"{what} cannot listen on {host}:{port}: "
                          f"{getattr(exc, 'strerror', None) or exc}") from None
    return sock


class Endpoint(ABC):
    """Where a monitor serves: the address, whether it is loopback, the token it requires.
    A server (the live monitor's, the replay's) says how it starts, runs and stops.

    Args:
        address: ``HOST:PORT`` (see :func:`parse_address`).
        token: the token to require (default: a fresh one when not bound to loopback).
    """

    def __init__(self, address: str | None = None, token: str | None = None) -> None:
        self.host, self.port = parse_address(address)
        self.loopback = is_loopback(self.host)
        self.token = token if token is not None else \
            (None if self.loopback else secrets.token_urlsafe(18))

    @property
    def address(self) -> str:
        """``HOST:PORT`` (IPv6 hosts in brackets)."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{host}:{self.port}"

    @property
    def url(self) -> str:
        """The page's address (with the token when one is needed)."""
        query = f"?token={self.token}" if self.token else ""
        return f"http://{self.address}/{query}"

    @property
    def hosts(self) -> set[str]:
        """The Host header values accepted on loopback."""
        return {"127.0.0.1", "localhost", "::1", self.host}

    @property
    @abstractmethod
    def running(self) -> bool:
        """Whether it serves (between ``start()`` and ``close()``)."""

    @abstractmethod
    def start(self) -> Endpoint:
        """Start serving; returns itself."""

    @abstractmethod
    def close(self) -> None:
        """Stop serving (safe twice)."""

    def __enter__(self) -> Any:
        return self if self.running else self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()


def _quiet(loop: Any, context: dict[str, Any]) -> None:
    """The server loop's errors (an accept that failed, ...) as one log line."""
    exc = context.get("exception")
    log.warning("the monitor's server: %s%s", context.get("message", "error"),
                f" ({type(exc).__name__}: {exc})" if exc is not None else "")


class MonitorServer(Endpoint):
    """The web server in a daemon thread; ``start()`` binds (errors are one line), ``close()``
    stops it (safe twice).

    Args:
        source: a :class:`LiveSource` or a replay source.
        address: ``HOST:PORT`` (see :func:`parse_address`).
        token: the token to require (default: a fresh one when not bound to loopback).
        limits: the bounds on clients (:class:`~relrl.monitor.bounds.Limits`).
    """

    def __init__(self, source: Any, address: str | None = None, *,
                 token: str | None = None, limits: Limits | None = None) -> None:
        super().__init__(address, token)
        self.source = source
        self.limits = limits or Limits()
        self._server: Any = None
        self._thread: threading.Thread | None = None
        self._sock: socket.socket | None = None

    def start(self, sock: socket.socket | None = None) -> MonitorServer:
        """Serve in the background, on ``sock`` when given (a listening socket), else on a
        socket bound to the address.

        Raises:
            ConfigError: the address cannot be bound (in use, not on this machine).
        """
        import uvicorn

        sock = sock if sock is not None else listen(self.host, self.port)
        self.port = sock.getsockname()[1]
        app = build_app(self.source, token=self.token, hosts=self.hosts)
        # uvicorn's own lines only for its errors: a client's bad request is not news on the
        # session's console (a flood of them would flood it)
        config = uvicorn.Config(app, http=bounded_protocol(self.limits), log_level="error",
                                access_log=False, lifespan="off", timeout_graceful_shutdown=1,
                                timeout_keep_alive=self.limits.idle_seconds,  # type: ignore
                                h11_max_incomplete_event_size=16 * 1024,
                                backlog=BACKLOG)  # also: accepted at once, at most
        self._server = server = uvicorn.Server(config)

        def run() -> None:
            async def serve() -> None:
                asyncio.get_running_loop().set_exception_handler(_quiet)
                await server.serve(sockets=[sock])

            asyncio.run(serve())

        self._thread = threading.Thread(target=run, name="relrl-monitor", daemon=True)
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
            if self._sock is not None:
                self._sock.close()
            self._server = None

    @property
    def running(self) -> bool:
        """Whether it serves."""
        return self._server is not None
