"""The hostile-recording corpus of ``relrl replay``: 46 cases, each one line naming the file
(and the line) and exit status 2, never a traceback, never a page served.

Each case is a small valid recording (``conftest.recording_files``) with one file changed --
bytes that are not UTF-8, lines that are not JSON objects, time units that are not whole
numbers, JSON nested 200,000 deep, values of the wrong type, symbolic links out of the
recording -- and the words the line must hold. The flags of ``relrl replay`` are in
``FLAG_CASES``. Symbolic links inside ``frames/`` (served, not loaded) are tested over HTTP
in ``test_hostile_requests.py``.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from relrl.cli import main
from tests.cli.conftest import one_line_exit_2
from tests.monitor.conftest import trace_line, write_recording

DEEP = b"[" * 200_000 + b"]" * 200_000
LINE1 = trace_line(1).encode() + b"\n"
LINE3 = b"\n" + trace_line(3).encode() + b"\n"
FRAME1 = b'{"index": 1, "t": 1, "file": "frames/000001.jpg"}\n'
FRAME3 = b'\n{"index": 2, "t": 3, "file": "frames/000002.jpg"}\n'


def _trace(line2: bytes | str) -> dict[str, bytes]:
    """The trace with ``line2`` as its second line."""
    return {"trace.jsonl": LINE1 + (line2.encode() if isinstance(line2, str) else line2)
            + LINE3}


def _frames(line2: bytes | str) -> dict[str, bytes]:
    return {"frames.jsonl": FRAME1 + (line2.encode() if isinstance(line2, str) else line2)
            + FRAME3}


def _json_file(name: str, content: bytes | str) -> dict[str, bytes]:
    return {name: content.encode() if isinstance(content, str) else content}


class Link:
    """A symbolic link to ``target`` (``{outside}``: a secret file outside the recording)."""

    def __init__(self, target: str) -> None:
        self.target = target


CASES: list[tuple[str, dict[str, object], list[str]]] = [
    # ---- trace.jsonl -----------------------------------------------------------------------
    ("trace-not-utf8", _trace(b'{"t": 2, "phase": "caf\xe9"}'),
     ["trace.jsonl:2", "not UTF-8", "0xe9"]),
    ("trace-row-array", _trace("[2, 3]"), ["trace.jsonl:2", "must be an object"]),
    ("trace-row-null", _trace("null"), ["trace.jsonl:2", "must be an object, not null"]),
    ("trace-row-number", _trace("2"), ["trace.jsonl:2", "must be an object"]),
    ("trace-t-missing", _trace('{"phase": "fruits"}'), ["trace.jsonl:2", "t is missing"]),
    ("trace-t-string", _trace('{"t": "2"}'), ["trace.jsonl:2", "t must be a whole number"]),
    ("trace-t-nan", _trace('{"t": NaN}'), ["trace.jsonl:2", "not NaN"]),
    ("trace-t-1e400", _trace('{"t": 1e400}'), ["trace.jsonl:2", "t must be a whole number"]),
    ("trace-t-fraction", _trace('{"t": 2.5}'), ["trace.jsonl:2", "not 2.5"]),
    ("trace-t-true", _trace('{"t": true}'), ["trace.jsonl:2", "not true"]),
    ("trace-t-negative", _trace('{"t": -1}'), ["trace.jsonl:2", "from 0 to 2**53"]),
    ("trace-t-5000-digits", _trace('{"t": ' + "7" * 5000 + "}"), ["trace.jsonl:2"]),
    ("trace-t-twice", _trace(trace_line(1)), ["trace.jsonl:2", "time unit 1 again"]),
    ("trace-deep", _trace(DEEP), ["trace.jsonl:2", "nested too deeply"]),
    ("trace-not-json", _trace("{t: 2}"), ["trace.jsonl:2", "not a JSON line"]),
    ("trace-activation-list", _trace(trace_line(2, activation=[0.5])),
     ["trace.jsonl:2", "activation must be an object"]),
    ("trace-activation-text", _trace(trace_line(2, activation={"socialize": "high"})),
     ["trace.jsonl:2", "activation.socialize must be a number"]),
    ("trace-ranked-item-null", _trace(trace_line(2, explanation={"ranked": [None]})),
     ["trace.jsonl:2", "explanation.ranked[0] must be an object"]),
    ("trace-memory-number", _trace(trace_line(2, memory=5)),
     ["trace.jsonl:2", "memory must be a list"]),
    ("trace-heard-text", _trace(trace_line(2, heard="apple")),
     ["trace.jsonl:2", "heard must be a list"]),
    ("trace-face-without-box", _trace(trace_line(2, overlay={"face": {"pose": "frontal"}})),
     ["trace.jsonl:2", "overlay.face.box is missing"]),
    ("trace-only-line-cut", {"trace.jsonl": b'{"t": 1, "pha'},
     ["trace.jsonl:1", "not a JSON line"]),
    ("trace-symlink", {"trace.jsonl": Link("{outside}")}, ["trace.jsonl", "symbolic link"]),
    ("trace-fifo", {"trace.jsonl": "fifo"}, ["trace.jsonl", "not a regular file"]),
    # ---- frames.jsonl ----------------------------------------------------------------------
    ("frames-not-utf8", _frames(b'{"index": 2, "t": 2, "file": "\xff"}'),
     ["frames.jsonl:2", "not UTF-8", "0xff"]),
    ("frames-row-array", _frames("[2]"), ["frames.jsonl:2", "must be an object"]),
    ("frames-row-null", _frames("null"), ["frames.jsonl:2", "must be an object"]),
    ("frames-t-missing", _frames('{"index": 2}'), ["frames.jsonl:2", "t is missing"]),
    ("frames-t-string", _frames('{"index": 2, "t": "2"}'),
     ["frames.jsonl:2", "t must be a whole number"]),
    ("frames-t-nan", _frames('{"index": 2, "t": NaN}'), ["frames.jsonl:2", "not NaN"]),
    ("frames-t-1e400", _frames('{"index": 2, "t": 1e400}'),
     ["frames.jsonl:2", "t must be a whole number"]),
    ("frames-deep", _frames(DEEP), ["frames.jsonl:2", "nested too deeply"]),
    ("frames-index-missing", _frames('{"t": 2}'), ["frames.jsonl:2", "index is missing"]),
    ("frames-index-zero", _frames('{"index": 0, "t": 2}'),
     ["frames.jsonl:2", "index must be a whole number from 1"]),
    ("frames-folder-symlink", {"frames/000001.jpg": None, "frames": Link("{outside_dir}")},
     ["frames", "symbolic link"]),
    # ---- trees.jsonl, events.jsonl -----------------------------------------------------------
    ("trees-without-graph", {"trees.jsonl": '{"t": 1}\n'}, ["trees.jsonl:1", "graph is missing"]),
    ("trees-graph-text", {"trees.jsonl": '{"t": 1, "graph": "a tree"}\n'},
     ["trees.jsonl:1", "graph must be an object"]),
    ("trees-nodes-object", {"trees.jsonl": '{"t": 1, "graph": {"nodes": {}}}\n'},
     ["trees.jsonl:1", "graph.nodes must be a list"]),
    ("events-row-array", {"events.jsonl": "[1]\n"}, ["events.jsonl:1", "must be an object"]),
    # ---- session.json, summary.json ----------------------------------------------------------
    ("summary-latin1", _json_file("summary.json", '{"episode": "caf\xe9"}'.encode("latin-1")),
     ["summary.json:1", "not UTF-8", "0xe9"]),
    ("session-latin1", _json_file("session.json", '{\n"episode": "caf\xe9"}'.encode("latin-1")),
     ["session.json:2", "not UTF-8"]),
    ("session-not-object", _json_file("session.json", "[1, 2]"),
     ["session.json:1", "not a JSON object"]),
    ("session-learner-text", _json_file("session.json", '{"seed": 1,\n "learner": "etg"}'),
     ["session.json:2", "learner must be an object"]),
    ("session-necessities-text", _json_file("session.json", '{"necessities": "socialize"}'),
     ["session.json:1", "necessities must be a list"]),
    ("summary-deep", _json_file("summary.json", DEEP), ["summary.json:1", "nested too deeply"]),
    ("session-symlink", {"session.json": Link("{outside}")},
     ["session.json", "symbolic link"]),
]

#: ``relrl replay`` flags that are no value: one line naming the flag and the value.
FLAG_CASES = [("nan", "nan"), ("-1", "-1.0"), ("0", "0.0"), ("inf", "inf")]


def _build(folder: Path, changes: dict[str, object], outside: Path) -> None:
    plain = {k: v for k, v in changes.items() if not isinstance(v, Link) and v != "fifo"}
    write_recording(folder, **plain)  # type: ignore[arg-type]
    for name, v in changes.items():
        path = folder / name
        if isinstance(v, Link):
            if path.is_dir() and not path.is_symlink():
                for f in path.iterdir():
                    f.unlink()
                path.rmdir()
            elif path.exists():
                path.unlink()
            path.symlink_to(v.target.format(outside=outside / "secret.txt",
                                            outside_dir=outside))
        elif v == "fifo":
            path.unlink()
            os.mkfifo(path)


@pytest.mark.parametrize("changes, needles", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_bad_recording_is_one_line_and_exit_2(capsys, tmp_path, changes, needles):
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "secret.txt").write_text('{"t": 1, "secret": "the lab\'s password"}\n')
    (outside / "000001.jpg").write_text("the lab's password\n")
    folder = tmp_path / "rec"
    _build(folder, changes, outside)
    line = one_line_exit_2(capsys, ["replay", str(folder), "--seconds", "0.2"], *needles)
    assert line.startswith(f"relrl replay: {folder}/") and "password" not in line


def test_the_corpus_holds_the_cases_it_says() -> None:
    """The module's first line says how many cases the corpus holds."""
    said = int(__doc__.split(":")[1].split()[0])
    assert said == len(CASES) and len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("value, shown", FLAG_CASES)
def test_replay_seconds_must_be_a_number_of_seconds(capsys, tmp_path, value, shown):
    folder = write_recording(tmp_path / "rec")
    one_line_exit_2(capsys, ["replay", str(folder), "--seconds", value], "--seconds", shown)


def test_the_good_recording_replays(capsys, tmp_path):
    """The base of every case is a recording replay serves (so each case's one change is
    what is refused)."""
    folder = write_recording(tmp_path / "rec")
    assert main(["replay", str(folder), "--seconds", "0.2"]) == 0
    assert "3 time units, 1 frames" in capsys.readouterr().out


def test_a_stopped_sessions_cut_last_line_is_left_out(tmp_path):
    from relrl.monitor.replay import Recording

    folder = write_recording(tmp_path / "rec", **{
        "trace.jsonl": LINE1 + trace_line(2).encode() + b"\n" + b'{"t": 3, "ph'})
    assert [r["t"] for r in Recording(folder).rows] == [1, 2]
    # a line that has its line end was written whole: being bad, it is an error
    folder = write_recording(tmp_path / "rec2", **{
        "trace.jsonl": LINE1 + trace_line(2).encode() + b"\n" + b'{"t": 3, "ph\n'})
    with pytest.raises(Exception, match="trace.jsonl:3"):
        Recording(folder)


def test_nan_in_a_recording_is_read_as_null(tmp_path):
    """``relrl run`` writes NaN when a policy's Q is NaN: replay keeps the recording and
    says null."""
    from relrl.monitor.replay import Recording

    folder = write_recording(tmp_path / "rec", **_trace(trace_line(2).replace(
        '"reward": -1.0', '"reward": NaN').replace('"q": 30.0', '"q": Infinity')))
    row = Recording(folder).row(2)
    assert row["reward"] is None and row["explanation"]["ranked"][0]["q"] is None
    assert json.dumps(row, allow_nan=False)
