"""What one connection to the monitor may hold: the server's side of a slow or hostile client.

uvicorn alone keeps a connection open as long as a client trickles its request headers
(slowloris), and accepts as many connections as there are file descriptors. The monitor's
HTTP protocol (:func:`bounded_protocol`, uvicorn's h11 protocol with a watchdog) adds, as a
careful web server does:

* **a connection cap** (:attr:`Limits.connections`): a connection beyond it is answered
  ``503`` and closed at once, so the server never holds more than that many descriptors
  for clients;
* **a request deadline** (:attr:`Limits.request_seconds`): the whole request (line, headers
  and any body) must arrive within it from the moment the server waits for one -- trickling
  a byte at a time does not extend it -- or the answer is ``408`` and the connection is
  closed;
* **a send deadline** (:attr:`Limits.send_seconds`): a client that takes none of what is sent
  to it for that long (a reader that never reads) is dropped, so a closing connection cannot
  linger either;
* idle keep-alive connections close after :attr:`Limits.idle_seconds` (uvicorn's own timer),
  and request heads are at most 16 KiB (h11's bound).
"""

from __future__ import annotations

import asyncio
from dataclasses import asdict, dataclass
from typing import Any

__all__ = ["Limits", "bounded_protocol"]

_BUSY = (b"HTTP/1.1 503 Service Unavailable\r\ncontent-type: text/plain; charset=utf-8\r\n"
         b"content-length: 43\r\nretry-after: 5\r\nconnection: close\r\n\r\n"
         b"the monitor has too many connections open\n")
_SLOW = (b"HTTP/1.1 408 Request Timeout\r\ncontent-type: text/plain; charset=utf-8\r\n"
         b"content-length: 41\r\nconnection: close\r\n\r\n"
         b"the request did not arrive in time: bye!\n")
#: seconds between two looks of a connection's watchdog, at most.
_TICK = 1.0


@dataclass(frozen=True)
class Limits:
    """The monitor server's bounds (see the module's text).

    Attributes:
        connections: client connections open at once, at most.
        request_seconds: seconds for a whole request to arrive.
        send_seconds: seconds a client may take nothing of what is sent to it.
        idle_seconds: seconds an idle keep-alive connection is kept.
    """

    connections: int = 64
    request_seconds: float = 10.0
    send_seconds: float = 30.0
    idle_seconds: float = 5.0

    def __post_init__(self) -> None:
        if not (isinstance(self.connections, int) and self.connections >= 1):
            raise ValueError(f"Limits.connections must be a whole number >= 1, not "
                             f"{self.connections!r}")
        for name in ("request_seconds", "send_seconds", "idle_seconds"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and 0 < value <= 3600):
                raise ValueError(f"Limits.{name} must be a number of seconds in (0, 3600], "
                                 f"not {value!r}")

    def as_dict(self) -> dict[str, Any]:
        """The limits as plain values (to hand them to another process)."""
        return asdict(self)


def bounded_protocol(limits: Limits) -> type:
    """uvicorn's h11 protocol class with ``limits`` applied (``uvicorn.Config(http=...)``)."""
    import h11
    from uvicorn.protocols.http.h11_impl import H11Protocol

    class BoundedH11(H11Protocol):
        """One client connection under :class:`Limits`: a watchdog looks at it at least
        once a second."""

        def connection_made(self, transport: Any) -> None:  # type: ignore[override]
            super().connection_made(transport)
            self._waiting: float | None = self.loop.time()  # waiting for a request since
            self._closing: float | None = None    # when this side began to close
            self._stalled: float | None = None    # sent data untaken since
            self._buffered = 0
            self._watch: asyncio.TimerHandle | None = self.loop.call_later(
                min(_TICK, limits.request_seconds), self._look)
            if len(self.connections) > limits.connections:
                self._close(_BUSY)

        def connection_lost(self, exc: Exception | None) -> None:
            if self._watch is not None:
                self._watch.cancel()
                self._watch = None
            super().connection_lost(exc)

        def data_received(self, data: bytes) -> None:
            super().data_received(data)
            if self.conn.their_state is not h11.IDLE and \
                    self.conn.their_state is not h11.SEND_BODY:
                self._waiting = None  # the whole request is in

        def on_response_complete(self) -> None:
            super().on_response_complete()
            if self.conn.their_state is h11.IDLE or self.conn.their_state is h11.SEND_BODY:
                self._waiting = self.loop.time()  # the next request's deadline starts

        def _close(self, answer: bytes | None = None) -> None:
            if self._closing is None:
                self._closing = self.loop.time()
                if answer is not None and self.conn.our_state is h11.IDLE:
                    self.transport.write(answer)
                self.transport.close()

        def _look(self) -> None:
            """The watchdog: request and send deadlines, and a close that does not end."""
            self._watch = None
            transport = self.transport
            if transport.is_closing() and self._closing is None:
                self._closing = self.loop.time()
            now = self.loop.time()
            size = transport.get_write_buffer_size()
            if size == 0 or size < self._buffered:
                self._stalled = None  # the client took some
            elif self._stalled is None:
                self._stalled = now
            self._buffered = size
            if (self._stalled is not None and now - self._stalled >= limits.send_seconds) or \
                    (self._closing is not None and now - self._closing >= limits.send_seconds):
                transport.abort()
                return
            if self._waiting is not None and self._closing is None and \
                    now - self._waiting >= limits.request_seconds:
                self._close(_SLOW)
            self._watch = self.loop.call_later(_TICK, self._look)

    return BoundedH11
