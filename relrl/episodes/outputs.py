"""The files a session writes into its output folder, and which names an episode's
``policy_save`` may not take (read when an episode script is checked, and by the session)."""

from __future__ import annotations

from pathlib import PurePosixPath

from relrl.tensorboard import EVENT_FILE

__all__ = ["NAME_MAX", "RECORDED", "RUN_FILES", "policy_save_problem"]

#: the files a recorded session writes besides the summary's (``--record``).
RECORDED = ("session.json", "episode.toml", "domain.pl", "session.mcap")
#: the files and folders (``name/``) a session writes into its output folder.
RUN_FILES = ("trace.jsonl", EVENT_FILE, "summary.json", "timing.json", "run.log",
             "rewards.png", "cgi.png", "table1.png") + RECORDED
#: the longest file name most file systems take, in bytes (the folder is asked at the run).
NAME_MAX = 255


def policy_save_problem(name: str) -> str | None:
    """Why ``name`` (a path inside the output folder) cannot be an episode's ``policy_save``:
    a NUL, a part longer than a file name can be, or a file or folder of the run itself
    (``summary.json``, ``session.json``, ``session.mcap``, relrl's ``.relrl-run.*``); None
    when it can."""
    if "\0" in name:
        return f"policy_save {name!r} holds a NUL character; no file name can"
    parts = PurePosixPath(name).parts
    for part in parts:
        if len(part.encode("utf-8", "surrogateescape")) > NAME_MAX:
            return (f"policy_save: the name {part[:40]}... is {len(part.encode())} bytes; a "
                    f"file name has at most {NAME_MAX}")
    if not parts:
        return None
    if {parts[0], f"{parts[0]}/"} & set(RUN_FILES) or parts[0].startswith(".relrl-run"):
        return (f"policy_save {name!r} is a file of the run itself; choose another name (e.g. "
                "policy.pl)")
    return None
