"""A monitor never hurts the session it watches: slowloris clients on loopback, bounded in
count and time, against a real ``relrl run --monitor`` whose descriptors are few (as on a
robot's computer with the usual limit of 1,024), and against the server's own bounds."""

from __future__ import annotations

import http.client
import json
import os
import re
import resource
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from relrl.monitor import start_replay
from relrl.monitor.replay import Recording, ReplaySource
from relrl.monitor.server import MonitorServer
from tests.conftest import default_signals
from tests.monitor.conftest import ROOT, Slowloris, episode, write_recording

pytestmark = pytest.mark.slow  # every test here takes a second or more

#: the session's descriptors: fewer than the attack's connections.
FD_LIMIT = 256
ATTACK = 300


def _bounded(folder: Path, **limits: float) -> MonitorServer:
    """Replay's server over ``folder`` with these limits."""
    from relrl.monitor.bounds import Limits

    return MonitorServer(ReplaySource(Recording(folder)), limits=Limits(**limits))


def _limited() -> None:
    default_signals()
    hard = resource.getrlimit(resource.RLIMIT_NOFILE)[1]
    resource.setrlimit(resource.RLIMIT_NOFILE, (FD_LIMIT, hard))


def _fds(pid: int | str = "self") -> int:
    return len(os.listdir(f"/proc/{pid}/fd"))


def _sockets(pid: int | str = "self") -> int:
    """The sockets a process holds."""
    n = 0
    for fd in os.listdir(f"/proc/{pid}/fd"):
        try:
            n += os.readlink(f"/proc/{pid}/fd/{fd}").startswith("socket:")
        except OSError:
            pass
    return n


def _lines(path: Path) -> int:
    try:
        return path.read_bytes().count(b"\n")
    except FileNotFoundError:
        return 0


def _wait(what, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while not what():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.05)


def _status(port: int, path: str = "/api/info") -> int:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        conn.request("GET", path)
        return conn.getresponse().status
    finally:
        conn.close()


def test_a_slowloris_cannot_cost_the_session_anything(tmp_path: Path) -> None:
    """300 connections that never finish their headers, against a session allowed 256
    descriptors: the session goes on, holds no descriptor more, and a Ctrl-C at the terminal
    still ends it with the summary, the policy and the run's record written; the page
    answers again once the attack has gone."""
    script = episode(tmp_path, steps=100_000, perception="symbolic")
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "relrl", "run", str(script), "--out", str(out), "--monitor",
         "--no-plots", "--step-seconds", "0.005"], cwd=ROOT, stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT, text=True, preexec_fn=_limited, start_new_session=True)
    try:
        assert proc.stdout is not None
        said = ""
        while "monitor: http" not in said:
            line = proc.stdout.readline()
            assert line, said
            said += line
        port = int(re.search(r"monitor: http://127\.0\.0\.1:(\d+)/", said).group(1))
        trace = out / "trace.jsonl"
        _wait(lambda: _lines(trace) >= 5)
        before = _fds(proc.pid)
        with Slowloris(port, ATTACK, 5) as attack:
            assert attack.opened >= ATTACK - 20  # the kernel took them: the attack is real
            time.sleep(1.5)
            during = _fds(proc.pid)
            units = _lines(trace)
            time.sleep(1.5)
            assert _lines(trace) > units, "the session stopped during the attack"
            answered, closed = attack.result()
        assert during <= before + 1, (before, during)  # the clients are not the robot's
        assert closed >= ATTACK - 70  # refused beyond the cap at once (503)
        assert _status(port) == 200  # the page is back once the attack has gone
        os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C at the terminal: the whole group
        rest, _ = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    said += rest
    assert proc.returncode == 128 + signal.SIGINT, said
    assert "Traceback" not in said and "Too many open files" not in said, said
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped_by"] == "SIGINT" and summary["steps"] == _lines(out / "trace.jsonl")
    assert "relrl_policy(" in (out / "policy.pl").read_text()
    record = json.loads((out / ".relrl-run.json").read_text())
    assert record["status"] == "partial" and "summary.json" in record["files"]


def test_the_server_holds_at_most_its_cap_and_drops_slow_requests(tmp_path: Path) -> None:
    """Replay's server (in this process): 40 slowloris connections against a cap of 8 --
    32 answered 503 at once, 8 answered 408 when their request's second ran out; this
    process never holds more than 8 of their sockets; then the page answers."""
    folder = write_recording(tmp_path / "rec")
    with _bounded(folder, connections=8, request_seconds=1.0, send_seconds=2.0) as server:
        assert _status(server.port) == 200  # serving: its event loop's own sockets are made
        before = _sockets()
        with Slowloris(server.port, 40, 6) as attack:
            time.sleep(0.4)
            during = _sockets()
            answered, closed = attack.result()
        assert attack.opened == 40
        assert during - before <= 8, (before, during)
        assert (answered, closed) == (40, 40)
        assert _status(server.port) == 200
        # the server closes its side of that last request on its own loop: give it a moment
        deadline = time.monotonic() + 3.0
        while _sockets() > before and time.monotonic() < deadline:
            time.sleep(0.05)
        assert _sockets() <= before


def test_a_request_trickled_a_byte_at_a_time_does_not_extend_its_deadline(tmp_path) -> None:
    folder = write_recording(tmp_path / "rec")
    with _bounded(folder, connections=8, request_seconds=1.0) as server, \
            socket.create_connection(("127.0.0.1", server.port), timeout=10) as s:
        start = time.monotonic()
        got = b""
        for byte in b"GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\nX-a: " + b"b" * 1000:
            try:
                s.send(bytes([byte]))
            except OSError:
                break
            s.settimeout(0.1)
            try:
                got = s.recv(4096)
            except TimeoutError:
                continue
            break
        assert got.startswith(b"HTTP/1.1 408"), got
        assert time.monotonic() - start < 1.0 + 2.5


def test_a_client_that_reads_nothing_is_dropped(tmp_path: Path) -> None:
    """A client asks for a large frame and takes none of it: after the send deadline the
    server lets the connection go rather than hold it (and its buffers) for ever."""
    size = 24 << 20
    folder = write_recording(tmp_path / "rec")
    (folder / "frames" / "000001.jpg").write_bytes(b"\xff\xd8" + bytes(size))
    with _bounded(folder, connections=8, send_seconds=1.0) as server:
        s = socket.socket()
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        s.connect(("127.0.0.1", server.port))
        s.sendall(b"GET /frames/1.jpg HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        time.sleep(1.0 + 2.5)  # read nothing meanwhile
        s.settimeout(10)
        got = 0
        try:
            while chunk := s.recv(1 << 20):
                got += len(chunk)
        except ConnectionResetError:
            pass
        s.close()
        assert got < size, "the server kept the connection until everything was sent"
        assert _status(server.port) == 200


def test_the_live_server_is_a_process_that_ends_with_the_robots(tmp_path: Path) -> None:
    """``kill -9`` of the session leaves no server behind."""
    script = episode(tmp_path, steps=100_000, perception="symbolic")
    proc = subprocess.Popen([sys.executable, "-m", "relrl", "run", str(script), "--monitor",
                             "--step-seconds", "0.01"], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, preexec_fn=default_signals)
    try:
        assert proc.stdout is not None
        while "monitor: http" not in (line := proc.stdout.readline()):
            assert line
        children = Path(f"/proc/{proc.pid}/task/{proc.pid}/children").read_text().split()
        assert len(children) == 1
        server = int(children[0])
        assert "relrl.monitor.live" in Path(f"/proc/{server}/cmdline").read_text()
        proc.kill()
        proc.communicate()
        _wait(lambda: not Path(f"/proc/{server}").exists()
              or "Z" in Path(f"/proc/{server}/stat").read_text().split()[2], timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()


def test_start_replay_still_serves_in_this_process(tmp_path: Path) -> None:
    folder = write_recording(tmp_path / "rec")
    with start_replay(folder) as server:
        assert isinstance(server, MonitorServer) and _status(server.port) == 200


def test_garbage_requests_print_nothing_on_the_sessions_console(tmp_path: Path) -> None:
    """A client's bad requests are not news on the session's terminal: 300 of them (bad
    request lines, bad headers, heads over 16 KiB) add no line to what the session prints --
    a flood of them would flood its console and its log."""
    script = episode(tmp_path, steps=100_000, perception="symbolic")
    proc = subprocess.Popen([sys.executable, "-m", "relrl", "run", str(script), "--monitor",
                             "--step-seconds", "0.01", "-q"], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, preexec_fn=default_signals)
    try:
        assert proc.stdout is not None
        said = proc.stdout.readline()
        port = int(re.search(r"monitor: http://127\.0\.0\.1:(\d+)/", said).group(1))
        for i in range(300):
            with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
                s.sendall([b"\x00\xff garbage\r\n\r\n", b"GET / HTTP/1.1\r\nHost\r\n\r\n",
                           b"GET / HTTP/1.1\r\nX: " + b"a" * 20000 + b"\r\n\r\n"][i % 3])
                assert s.recv(4096).startswith(b"HTTP/1.1 4")
        assert _status(port) == 200
        proc.send_signal(signal.SIGINT)
        rest, _ = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 128 + signal.SIGINT
    lines = [x for x in rest.splitlines() if x.strip()]
    assert not [x for x in lines if "HTTP" in x or "request" in x.lower()], lines
    assert len(lines) <= 8, lines  # the summary and the stop message, nothing per request


def test_a_server_process_that_dies_costs_the_session_nothing(tmp_path: Path) -> None:
    """``kill -9`` of the monitor's process: the session says so in one line and goes on to
    its end, with everything written."""
    script = episode(tmp_path, steps=400, perception="symbolic")
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "relrl", "run", str(script), "--monitor",
                             "--out", str(out), "--no-plots", "--step-seconds", "0.01", "-q"],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, preexec_fn=default_signals)
    try:
        assert proc.stdout is not None
        said = proc.stdout.readline()
        assert "monitor: http" in said, said
        children = Path(f"/proc/{proc.pid}/task/{proc.pid}/children").read_text().split()
        _wait(lambda: _lines(out / "trace.jsonl") >= 20)
        os.kill(int(children[0]), signal.SIGKILL)
        rest, _ = proc.communicate(timeout=180)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, said + rest
    assert rest.count("the monitor stopped serving") == 1 and "Traceback" not in rest, rest
    assert json.loads((out / "summary.json").read_text())["steps"] == 400
