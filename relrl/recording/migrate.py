"""Sessions recorded as a folder of frames by earlier relrl, converted to ``session.mcap``.

Earlier relrl recorded a session (``--record``) as ``frames/000001.jpg ...`` with
``frames.jsonl``, ``trees.jsonl`` and ``events.jsonl`` beside the trace. A session is now one
MCAP file; :func:`migrate_folder` (``relrl migrate DIR``) writes ``DIR/session.mcap`` from
those files -- the trace rows into the per-unit channels, the JPEG frames as they are (not
encoded again), the trees and events, ``session.json`` and ``summary.json`` as metadata, the
script and domain attached -- and keeps every old file. The old folder held no wall clock per
time unit: the units are spread evenly over the session's recorded duration
(``session.json``'s ``seconds``), from when it was recorded.
"""

from __future__ import annotations

import datetime as _dt
import math
from pathlib import Path
from typing import Any

from relrl.errors import UserError
from relrl.recording.channels import (
    ANNOTATIONS,
    DESCRIPTION,
    EVENTS,
    IMAGE,
    PERCEPTION,
    SCENE,
    SESSION,
    TRANSFORMS,
    TREE,
    annotations_of,
    cdr_encoders,
    joint_state_of,
    split_row,
    to_json,
)
from relrl.recording.channels import JOINTS as JOINT_STATES

__all__ = ["migrate_folder"]


#: a message's time in an MCAP file is an unsigned 64-bit count of nanoseconds.
_NS_END = 2**64
#: the longest session duration read from ``session.json`` (a year, in seconds).
MAX_SECONDS = 366 * 24 * 3600


def _per_unit(manifest: dict[str, Any], units: int, where: Path) -> int:
    """Nanoseconds per time unit: the session's recorded duration spread over its units
    (a tenth of a second each when ``seconds`` is not recorded)."""
    seconds = manifest.get("seconds")
    if seconds is None or seconds == 0:
        return 100_000_000
    if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) or \
            not math.isfinite(seconds) or not 0 < seconds <= MAX_SECONDS:
        raise UserError(f"{where}: seconds must be a number above 0 and at most "
                        f"{MAX_SECONDS:,} (a year), not {seconds!r}")
    return max(1, int(1e9 * seconds / units))


def _start_ns(manifest: dict[str, Any], folder: Path) -> int:
    stamp = manifest.get("recorded")
    if isinstance(stamp, str):
        try:
            return int(_dt.datetime.strptime(stamp, "%Y-%m-%dT%H:%M:%S%z").timestamp() * 1e9)
        except ValueError:
            pass
    return int((folder / "trace.jsonl").stat().st_mtime * 1e9)


def migrate_folder(folder: str | Path) -> Path:
    """Write ``FOLDER/session.mcap`` from a session recorded as a folder of frames.

    Returns:
        the file written.

    Raises:
        UserError: not such a folder, already migrated, or a damaged file in it.
    """
    from relrl.monitor.replay import Recording
    from relrl.recording.mcapfile import McapFile

    folder = Path(folder)
    target = folder / "session.mcap"
    if target.exists():
        raise UserError(f"{target}: already there; the folder needs no migration")
    old = Recording(folder)  # the folder's reader: its errors name the file and line
    rows, frames, manifest, summary = old.rows, old.frames, old.manifest, old.summary
    if not rows:
        raise UserError(f"{folder}/trace.jsonl: no time unit recorded; nothing to migrate")
    start = _start_ns(manifest, folder)
    per_unit = _per_unit(manifest, len(rows), folder / "session.json")
    first = int(rows[0]["t"])
    for n, event in enumerate(old.events, 1):
        if "t" not in event:
            raise UserError(f"{folder}/events.jsonl: event {n} has no t (the time unit it "
                            "happened in)")
    times = [int(x["t"]) for x in (*rows, *frames, *old.trees, *old.events)]
    ends = (start + (min(times) - first) * per_unit, start + (max(times) - first) * per_unit)
    if ends[0] < 0 or ends[1] >= _NS_END:
        raise UserError(f"{folder}/session.json: the session's clock (recorded "
                        f"{manifest.get('recorded')!r}, {len(rows)} units over "
                        f"{manifest.get('seconds')!r} s) runs outside 1970 to 2554, the "
                        "times an MCAP file holds")

    def at(t: int) -> int:  # the session's clock, units spread evenly over its duration
        return start + (int(t) - first) * per_unit

    from relrl.recording.scene import SceneEncoder, encode_annotations

    cdr = cdr_encoders()
    scene = SceneEncoder()
    by_frame = {int(f["index"]): f for f in frames}
    out = McapFile(target, library="relrl migrate")
    try:
        out.write(SESSION, start, to_json({k: manifest.get(k) for k in (
            "episode", "seed", "steps", "necessities", "responses", "where", "perception")}
            | {"learner": (manifest.get("learner") or {}).get("name")}))
        out.write(DESCRIPTION, start, cdr[DESCRIPTION.topic]({"data": scene.description}))
        messages: list[tuple[int, int, Any, bytes]] = []  # (ns, order, channel, data)
        for row in rows:
            ns = at(row["t"])
            for ch, msg in split_row(row):
                messages.append((ns, len(messages), ch, to_json(msg)))
            if row.get("head"):
                joints = joint_state_of(row["head"], ns)
                messages.append((ns, len(messages), JOINT_STATES,
                                 cdr[JOINT_STATES.topic](joints)))
                positions = dict(zip(joints["name"], joints["position"], strict=True))
                messages.append((ns, len(messages), TRANSFORMS,
                                 scene.transforms(ns, positions)))
                messages.append((ns, len(messages), SCENE, scene.scene(ns, row.get("overlay"))))
        seen = {r.get("frame"): r for r in rows if r.get("frame")}
        for index, entry in sorted(by_frame.items()):
            jpeg = old.frame_bytes(index)
            if jpeg is None:
                raise UserError(f"{folder}/frames/{index:06d}.jpg: frame {index} of "
                                "frames.jsonl is missing")
            ns = at(entry["t"])
            stamp = {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}
            if index not in seen:  # the last frame, after the last unit
                messages.append((ns, len(messages), PERCEPTION, to_json(
                    {"t": entry["t"], "overlay": None, "frame": index,
                     "frame_looking_at": entry.get("looking_at")})))
            messages.append((ns, len(messages), IMAGE, cdr[IMAGE.topic](
                {"header": {"stamp": stamp, "frame_id": "camera"}, "format": "jpeg",
                 "data": jpeg})))
            overlay = (seen.get(index) or {}).get("overlay")
            messages.append((ns, len(messages), ANNOTATIONS,
                             encode_annotations(annotations_of(overlay, ns))))
        for tree in old.trees:
            messages.append((at(tree["t"]), len(messages), TREE,
                             to_json({"t": tree["t"], "graph": tree.get("graph")})))
        for event in old.events:
            messages.append((at(event["t"]), len(messages), EVENTS, to_json(event)))
        for ns, _, ch, data in sorted(messages, key=lambda m: (m[0], m[1])):
            out.write(ch, ns, data)
        for name in ("episode.toml", "domain.pl"):
            if (folder / name).is_file():
                out.add_attachment(name, "text/plain", (folder / name).read_bytes())
        for name, value in (("relrl.session", manifest), ("relrl.summary", summary)):
            if value:
                out.add_metadata(name, {"json": to_json(value).decode()})
    except BaseException:
        out.close()
        target.unlink(missing_ok=True)
        raise
    out.close()
    return target
