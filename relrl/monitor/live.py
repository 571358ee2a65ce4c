"""The live monitor's web server in a process of its own, so that no client can hurt the
session it watches.

In the robot's process the control loop hands views to a :class:`~relrl.monitor.hub.Hub` as
before; a feeder thread sends what changed (:meth:`Hub.changes`: the view, new points of the
necessity plot, the tree, the newest frame as JPEG) at the hub's rate over a socket pair to a
child process (``python -m relrl.monitor.live``), which keeps a hub of its own
(:meth:`Hub.apply`) and serves it with :class:`~relrl.monitor.server.MonitorServer`.

What this buys, measured (docs/monitor.md): every client connection, every request's work,
the tree's drawing by ``dot`` and any descriptor or memory a client can make the server use
are the child's, not the robot's. The robot's process holds one socket for the monitor
whatever the clients do; its descriptors, its saves of the partial results on a stop, and its
share of the interpreter lock are untouched. The child runs at a lower priority (nice +10)
and is the first the kernel's out-of-memory killer picks.

Life cycle: the parent binds the listening socket (so a bad address is a one-line error at
start) and hands it to the child; the child ignores Ctrl-C and the terminal's hang-up (the
robot decides when the session ends) and exits when the feed closes -- when the robot's
process closes the monitor, ends, or is killed.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import pickle
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

from relrl.errors import ConfigError
from relrl.monitor.bounds import Limits
from relrl.monitor.server import Endpoint, listen

__all__ = ["LiveServer"]

log = logging.getLogger(__name__)

_HEADER = struct.Struct("!Q")
#: seconds the child may take to start serving (a loaded machine imports slowly).
START_SECONDS = 60.0
#: seconds close() waits for the last update to be sent and for the child to end.
CLOSE_SECONDS = 3.0
#: the child's priority below the robot's (nice), and how readily it is killed first when
#: memory runs out (oom_score_adj).
NICE, OOM_SCORE_ADJ = 10, 500


def _send(sock: socket.socket, data: bytes) -> None:
    sock.sendall(_HEADER.pack(len(data)) + data)


def _recv_exactly(sock: socket.socket, n: int) -> bytes | None:
    chunks, left = [], n
    while left:
        chunk = sock.recv(min(left, 1 << 20))
        if not chunk:
            return None
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def _recv(sock: socket.socket) -> Any:
    """The next update from the feed, ``None`` when it has closed."""
    head = _recv_exactly(sock, _HEADER.size)
    if head is None:
        return None
    body = _recv_exactly(sock, _HEADER.unpack(head)[0])
    return None if body is None else pickle.loads(body)  # noqa: S301 - our own parent


class LiveServer(Endpoint):
    """The live page of ``hub``, served by a child process; the same face as
    :class:`~relrl.monitor.server.MonitorServer` (``url``, ``port``, ``token``, ``start()``,
    ``close()`` safe twice, a context manager).

    Args:
        hub: the session's hub.
        address: ``HOST:PORT`` (see :func:`~relrl.monitor.server.parse_address`).
        token: the token to require (default: a fresh one when not bound to loopback).
        limits: the bounds on clients (:class:`~relrl.monitor.bounds.Limits`).
    """

    def __init__(self, hub: Any, address: str | None = None, *, token: str | None = None,
                 limits: Limits | None = None) -> None:
        super().__init__(address, token)
        self.hub = hub
        self.limits = limits or Limits()
        self.process: subprocess.Popen[bytes] | None = None
        self._feed: socket.socket | None = None
        self._thread: threading.Thread | None = None
        self._closing = threading.Event()
        self._mark: dict[str, int] = {}

    def start(self) -> LiveServer:
        """Bind, start the serving process and wait until it serves.

        Raises:
            ConfigError: the address cannot be bound, or the process did not start.
        """
        try:
            import starlette  # noqa: F401
            import uvicorn  # noqa: F401
        except ImportError:
            raise ConfigError("the monitor needs the optional extra: pip install "
                              "'relrl[monitor]' (starlette, uvicorn)") from None
        listener = listen(self.host, self.port)
        self.port = listener.getsockname()[1]
        feed, theirs = socket.socketpair()
        config = {"rate": self.hub.rate, "address": self.address, "token": self.token,
                  "limits": self.limits.as_dict(), "listen_fd": listener.fileno(),
                  "feed_fd": theirs.fileno()}
        env = dict(os.environ)
        root = str(Path(__file__).resolve().parents[2])  # relrl importable from a checkout
        env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
        try:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "relrl.monitor.live", json.dumps(config)],
                pass_fds=(listener.fileno(), theirs.fileno()), stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL, env=env, close_fds=True)
        finally:
            listener.close()  # the child's now: this process holds no client's socket
            theirs.close()
        self._feed = feed
        try:
            feed.settimeout(START_SECONDS)
            self._feed_once()  # the state at start, before the child serves
            ready = feed.recv(1)
            feed.settimeout(None)
        except OSError:
            ready = b""
        if ready != b"R":
            code = self.process.poll()
            self.close()
            raise ConfigError("the monitor's server process did not start"
                              + (f" (exit status {code})" if code is not None else ""))
        self._thread = threading.Thread(target=self._feeding, name="relrl-monitor-feed",
                                        daemon=True)
        self._thread.start()
        return self

    def _feed_once(self) -> None:
        update = self.hub.changes(self._mark)
        if update is not None and self._feed is not None:
            _send(self._feed, pickle.dumps(update, protocol=pickle.HIGHEST_PROTOCOL))

    def _feeding(self) -> None:
        """The feeder thread: what changed, at twice the hub's rate; a child that is slow
        only holds up this thread, never the control loop."""
        period = self.hub.period / 2
        try:
            while not self._closing.wait(period):
                self._feed_once()
            self._feed_once()  # the last state (the session's end)
        except Exception as exc:  # noqa: BLE001 - a side thread: said, never raised
            # the child ended, or a view could not be sent: the robot goes on without a page
            if not self._closing.is_set():
                log.warning("the monitor stopped serving (%s: %s); the session goes on",
                            type(exc).__name__, exc)

    def close(self) -> None:
        """Send the last state, end the serving process (safe twice)."""
        self._closing.set()
        if self._thread is not None:
            self._thread.join(CLOSE_SECONDS)
            if self._thread.is_alive() and self._feed is not None:  # the child is stuck
                with contextlib.suppress(OSError):
                    self._feed.shutdown(socket.SHUT_RDWR)
                self._thread.join(CLOSE_SECONDS)
            self._thread = None
        if self._feed is not None:
            self._feed.close()  # the child sees the feed end and stops serving
            self._feed = None
        if self.process is not None:
            try:
                self.process.wait(CLOSE_SECONDS)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
            self.process = None

    @property
    def running(self) -> bool:
        """Whether its process serves."""
        return self.process is not None


def _settle() -> None:
    """This process yields to the robot's (nice, and first to go when memory runs out) and
    may use every descriptor the system allows it: they are not the robot's."""
    import resource

    with contextlib.suppress(OSError):
        os.nice(NICE)
    with contextlib.suppress(OSError), open("/proc/self/oom_score_adj", "w") as fh:
        fh.write(str(OOM_SCORE_ADJ))
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    with contextlib.suppress(ValueError, OSError):
        resource.setrlimit(resource.RLIMIT_NOFILE, (max(soft, min(hard, 4096)), hard))


def _child(config: dict[str, Any]) -> int:
    """The serving process: a hub fed from the parent, served until the feed closes."""
    from relrl.monitor.hub import Hub
    from relrl.monitor.server import LiveSource, MonitorServer

    for sig in (signal.SIGINT, signal.SIGHUP):
        signal.signal(sig, signal.SIG_IGN)  # the robot's process decides when it ends
    _settle()
    logging.basicConfig(level=logging.WARNING, format="relrl: %(message)s")
    feed = socket.socket(fileno=config["feed_fd"])
    listener = socket.socket(fileno=config["listen_fd"])
    hub = Hub(config["rate"])
    first = _recv(feed)
    if first is None:
        return 0
    hub.apply(first)
    server = MonitorServer(LiveSource(hub), config["address"], token=config["token"],
                           limits=Limits(**config["limits"]))
    server.start(listener)
    feed.sendall(b"R")
    try:
        while (update := _recv(feed)) is not None:
            hub.apply(update)
    except OSError:
        pass
    finally:
        hub.finish()
        time.sleep(min(0.5, 2 * hub.period))  # open event streams see the end
        server.close()
    return 0


if __name__ == "__main__":
    sys.exit(_child(json.loads(sys.argv[1])))
