"""Where commands write: one policy for every ``--out`` folder, one writer for every file.

The policy (``docs/outputs.md``):

* ``--out DIR`` names the folder. It is created when missing. A folder that already holds
  files is refused (exit 2) unless ``--overwrite`` is given; then the files the earlier relrl
  run wrote there are deleted first -- those its record lists, or, for a run killed before it
  finished its record, those its journal names -- so no stale file of that run sits beside
  the new ones; every other file is kept. A folder without a record is never emptied.
* One command at a time: a claimed folder is locked (``flock`` on the folder itself, let go
  by the kernel even after ``kill -9``); a second command on it is refused (exit 2).
* Without ``--out``, ``relrl experiment``, ``relrl demo`` and the Experiment 2 sweep write a
  fresh folder ``runs/NAME-YYYYMMDD-HHMMSS`` (``-2``, ``-3``... when taken): re-running
  never mixes runs.
* Everything is checked before any work starts: a path that is a file or a device, lies
  under a file, or cannot be created or written -- and an output of the command that is a
  link or lies under one (``OutDir.claim(outputs=...)``) -- is one line and exit 2, not a
  traceback after an hour of experiment.
* Every file goes through this module. Inside a claimed folder nothing is written through a
  symbolic link -- neither a link at the file's name nor a linked subfolder (``frames/``):
  the folder is walked with ``O_NOFOLLOW`` from a descriptor held since the claim, so a folder
  deleted or moved during the run is noticed rather than re-created.
* Whole files (:func:`write_atomic`) are written atomically: a new temporary file in the same
  folder, ``fsync``, a rename; mode 0644 (0666 less the umask); a failed write -- a full disk
  included -- leaves no temporary file. Streams (:func:`open_stream`: trace, log, index) are
  new files (never a file or link that was there) written a whole record at a time; a record
  that does not fit is cut off, so the file ends at the last whole record.
* 64 KiB are held back in the folder while the command works (``.relrl-run.spare``) and given
  back when a result (not a figure, a table or a frame: those pass ``spare=False``) meets a
  full disk, so the summary and the policy still go where they fit; the first record takes
  room for the last, so a full disk never leaves it saying ``running``.
* ``.relrl-run.json`` records the command, when it started and ended, whether it finished
  (``complete``) or stopped early (``partial``), and the files it wrote; while the command
  works ``.relrl-run.files`` journals each name before the file is created.

Example::

    with OutDir.claim("runs/exp1", command="relrl experiment sis") as out:
        write_json_atomic(out.path / "results.json", results)
        out.status = "complete"
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
from typing import Any

from relrl.errors import OutputError
from relrl.outdir.claim import MANIFEST, OutDir, claim_of, timestamped
from relrl.outdir.fs import (
    O_DIR,
    Stream,
    deferred_signals,
    file_mode,
    is_special,
    new_file_in,
    open_folder,
    reason,
    refuse_nul,
    way_problem,
    write_in,
)

__all__ = ["MANIFEST", "OutDir", "Stream", "add_out_options", "check_inside", "check_out_file",
           "deferred_signals", "file_mode", "open_stream", "timestamped",
           "write_atomic", "write_json_atomic"]


def write_atomic(path: str | Path, data: bytes | str, *, spare: bool = True) -> Path:
    """Write ``data`` to ``path`` whole, through a temporary file and a rename (mode 0644).

    Inside a claimed folder (:meth:`OutDir.claim`) the write goes through the claim (no link
    followed, the name journalled). Elsewhere a link at ``path`` is refused, and a device or
    pipe (``/dev/null``, ``/dev/stdout``) is written in place. A failure removes the
    temporary file and raises :class:`OutputError` naming the path.

    Args:
        path: the file.
        data: its content (``str`` is written as UTF-8).
        spare: inside a claimed folder, whether a full disk may use the space held back
            (``False`` for bulk: frames, figures, tables).
    """
    p = Path(path)
    refuse_nul(p, "cannot write")
    claimed = claim_of(p)
    if claimed is not None:
        out, parts = claimed
        return out.write("/".join(parts), data, spare=spare)
    raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    if is_special(p):
        try:
            with open(p, "wb") as fh:
                fh.write(raw)
        except OSError as exc:
            raise OutputError(f"cannot write {p}: {reason(exc)}") from None
        return p
    dir_fd = _folder_of(p)
    try:
        write_in(dir_fd, p.name, raw, p)
    except OSError as exc:
        raise OutputError(f"cannot write {p}: {reason(exc)}") from None
    finally:
        os.close(dir_fd)
    return p


def _folder_of(p: Path) -> int:
    """A descriptor of the folder of ``p`` (outside any claim), created when missing."""
    try:
        os.makedirs(p.parent, exist_ok=True)
        return os.open(p.parent, O_DIR)
    except OSError as exc:
        raise OutputError(f"cannot write {p}: {reason(exc)}") from None


def write_json_atomic(path: str | Path, data: Any) -> Path:
    """Write ``data`` as indented, key-sorted JSON (see :func:`write_atomic`)."""
    return write_atomic(path, json.dumps(data, indent=1, sort_keys=True) + "\n")


def open_stream(path: str | Path, *, binary: bool = False) -> Stream:
    """A new file at ``path`` written a record at a time (a trace, a log, an index).

    Whatever was at ``path`` is replaced, never written through; inside a claimed folder the
    name is journalled and no link is followed.

    Raises:
        OutputError: the file cannot be created.
    """
    p = Path(path)
    refuse_nul(p, "cannot write")
    claimed = claim_of(p)
    if claimed is not None:
        out, parts = claimed
        return out.stream("/".join(parts), binary=binary)
    dir_fd = _folder_of(p)
    try:
        return Stream(new_file_in(dir_fd, p.name, p), p, binary)
    except OSError as exc:
        raise OutputError(f"cannot write {p}: {reason(exc)}") from None
    finally:
        os.close(dir_fd)


def check_inside(folder: str | Path, rel: str) -> None:
    """Refuse ``rel`` (a path inside ``folder``) when writing it would follow a link or meet
    a file or folder in the way -- for writes outside a claimed folder, which the writer
    cannot walk itself (a claimed folder's writes are checked as they go).

    Raises:
        OutputError: naming the part in the way.
    """
    folder = Path(folder)
    try:
        fd = os.open(folder, O_DIR)
    except OSError as exc:
        raise OutputError(f"cannot write into {folder}: {reason(exc)}") from None
    try:
        problem = way_problem(fd, rel)
    finally:
        os.close(fd)
    if problem:
        raise OutputError(f"{folder}: {problem}")


def check_out_file(path: str | Path, what: str, *, suffixes: tuple[str, ...] = (),
                   devices: bool = True) -> Path:
    """Check an output file before the work that produces it; create its folder.

    Args:
        path: the file to be written later.
        what: the option, for messages (``--json``, ``--annotate``, ``-o``).
        suffixes: allowed file name endings (lower case), e.g. ``(".png", ".jpg")``.
        devices: accept a device or pipe (``/dev/null``, ``/dev/stdout``), written in place.

    Returns:
        The path.

    Raises:
        OutputError: the path is a folder (or a device, unless ``devices``) or a link, lies
            under a file, has a suffix not in ``suffixes``, or its folder cannot be created
            or written.
    """
    p = Path(path)
    refuse_nul(p, what)
    if p.is_dir():
        raise OutputError(f"{what} {p}: is a folder; give a file name")
    if is_special(p) and not devices:
        raise OutputError(f"{what} {p}: not a regular file; give a file name")
    if suffixes and p.suffix.lower() not in suffixes and not is_special(p):
        raise OutputError(f"{what} {p}: unknown file type {p.suffix or '(none)'!r}; "
                          f"use {', '.join(suffixes)}")
    if is_special(p):
        return p
    if p.is_symlink():
        raise OutputError(f"{what} {p}: is a symbolic link; relrl writes nothing through a "
                          "link (give the file's own path)")
    os.close(open_folder(p.parent, what))
    return p


def add_out_options(parser: argparse.ArgumentParser, *, default: str | None,
                    what: str = "output folder") -> None:
    """Add ``--out DIR`` and ``--overwrite`` to a subcommand's parser.

    Args:
        parser: the subcommand's parser.
        default: the base of the fresh timestamped folder written without ``--out``
            (``None``: nothing is written without ``--out``).
        what: what goes into the folder, for the help text.
    """
    fresh = (f" (default: a new folder {default}-YYYYMMDD-HHMMSS)" if default
             else " (default: write nothing)")
    parser.add_argument("--out", default=None, metavar="DIR",
                        help=f"{what}; refused when it holds files, unless --overwrite{fresh}")
    parser.add_argument("--overwrite", action="store_true",
                        help="reuse a non-empty --out folder: the files of the earlier run "
                             "there are deleted first (files relrl did not write are kept)")
