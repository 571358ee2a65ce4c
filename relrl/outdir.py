"""Where commands write: one policy for every ``--out`` folder and every output file.

The policy (``docs/outputs.md``):

* ``--out DIR`` names the folder. It is created when missing. A folder that already holds
  files is refused (exit 2) unless ``--overwrite`` is given; then the files the earlier relrl
  run wrote there (listed in its ``.relrl-run.json``) are deleted first, so no stale file of
  that run sits beside the new ones; other files are kept (a run killed before finishing its
  record owns everything but what it found there). A folder without a record is never
  emptied.
* Without ``--out``, ``relrl experiment`` and ``relrl demo`` write a fresh folder
  ``runs/NAME-YYYYMMDD-HHMMSS`` (``-2``, ``-3``... when taken): re-running never mixes runs.
* Everything is checked before any work starts: a path that is a file or a device, lies
  under a file, or cannot be created or written is one line and exit 2, not a traceback
  after an hour of experiment.
* Files are written atomically (a temporary file in the same folder, then a rename) with
  mode 0644 (0666 less the umask); a failed write leaves no temporary file behind.
* ``.relrl-run.json`` in each folder records the command, when it started and ended, whether
  it finished (``complete``) or stopped early (``partial``), and the files it wrote.

Example::

    with OutDir.claim("runs/exp1", command="relrl experiment sis") as out:
        write_json_atomic(out.path / "results.json", results)
        out.status = "complete"
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import json
import os
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from relrl.errors import OutputError

__all__ = ["MANIFEST", "OutDir", "add_out_options", "check_out_file", "file_mode",
           "timestamped", "write_atomic", "write_json_atomic"]

#: the record of the run that wrote a folder.
MANIFEST = ".relrl-run.json"


def file_mode() -> int:
    """The mode of the files relrl writes: 0666 less the process umask (0644 usually)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return 0o666 & ~mask


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc)


def _special(path: Path) -> bool:
    """A device or a pipe (``/dev/null``, ``/dev/stdout``): written in place, never renamed."""
    try:
        mode = path.stat().st_mode
    except OSError:
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


def _probe(folder: Path, what: str) -> None:
    """Raise :class:`OutputError` unless a file can be created in ``folder``."""
    try:
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".relrl-probe.", suffix=".tmp")
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise OutputError(f"{what} {folder}: cannot write there ({_reason(exc)})") from None


def _make_folder(path: Path, what: str) -> None:
    if path.exists() and not path.is_dir():
        raise OutputError(f"{what} {path}: is not a folder (a file or device is there); "
                          "give a folder name")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OutputError(f"{what} {path}: a file is in the way; give a folder name") from None
    except NotADirectoryError:
        raise OutputError(f"{what} {path}: a part of the path is a file, not a folder") \
            from None
    except OSError as exc:
        raise OutputError(f"{what} {path}: cannot create the folder ({_reason(exc)})") \
            from None


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
        OutputError: the path is a folder (or a device, unless ``devices``), lies under a
            file, has a suffix not in ``suffixes``, or its folder cannot be created or
            written.
    """
    p = Path(path)
    if p.is_dir():
        raise OutputError(f"{what} {p}: is a folder; give a file name")
    if _special(p) and not devices:
        raise OutputError(f"{what} {p}: not a regular file; give a file name")
    if suffixes and p.suffix.lower() not in suffixes and not _special(p):
        raise OutputError(f"{what} {p}: unknown file type {p.suffix or '(none)'!r}; "
                          f"use {', '.join(suffixes)}")
    if _special(p):
        return p
    parent = p.parent
    _make_folder(parent, what)
    _probe(parent, what)
    return p


def write_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename (mode 0644).

    A device or pipe (``/dev/null``) is written in place. A failure removes the temporary
    file and raises :class:`OutputError` naming the path.
    """
    p = Path(path)
    raw = data.encode("utf-8") if isinstance(data, str) else data
    try:
        if _special(p):
            with open(p, "wb") as fh:
                fh.write(raw)
            return p
        if p.is_dir():
            raise IsADirectoryError(21, "is a folder")
        fd, tmp = tempfile.mkstemp(dir=p.parent, prefix=f".{p.name}.", suffix=".tmp")
    except OSError as exc:
        raise OutputError(f"cannot write {p}: {_reason(exc)}") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(raw)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, file_mode())
        os.replace(tmp, p)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise OutputError(f"cannot write {p}: {_reason(exc)}") from None
        raise
    return p


def write_json_atomic(path: str | Path, data: Any) -> Path:
    """Write ``data`` as indented, key-sorted JSON (see :func:`write_atomic`)."""
    return write_atomic(path, json.dumps(data, indent=1, sort_keys=True) + "\n")


def timestamped(base: str | Path) -> Path:
    """A folder name ``BASE-YYYYMMDD-HHMMSS`` that does not exist yet (``-2``... if taken)."""
    stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    first = Path(f"{base}-{stamp}")
    candidate, n = first, 1
    while candidate.exists():
        n += 1
        candidate = Path(f"{first}-{n}")
    return candidate


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


def _files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")
            if (p.is_file() or p.is_symlink()) and p.name != MANIFEST}


class OutDir:
    """An output folder claimed by one command (see the module's policy).

    Attributes:
        path: the folder.
        status: ``complete`` once the caller says so; left ``partial`` otherwise.
    """

    def __init__(self, path: Path, command: str, foreign: set[str]) -> None:
        self.path = path
        self.command = command
        self.status = "running"
        self._foreign = foreign
        self._started = _dt.datetime.now().isoformat(timespec="seconds")
        self._record()

    @classmethod
    @contextlib.contextmanager
    def claim(cls, path: str | Path | None, *, command: str, overwrite: bool = False,
              default: str | None = None, what: str = "--out") -> Iterator[OutDir]:
        """Claim an output folder for the block; the record is finished on exit.

        Args:
            path: the folder (``None``: a fresh :func:`timestamped` folder from ``default``).
            command: the command line, for the record.
            overwrite: replace an earlier run's files instead of refusing a non-empty folder.
            default: the base name of the timestamped folder when ``path`` is ``None``.
            what: the option, for messages.

        Raises:
            OutputError: the folder is not usable, or not empty without ``overwrite``.
        """
        if path is None:
            if default is None:
                raise ValueError("OutDir.claim needs a path or a default")
            target = timestamped(default)
        else:
            target = Path(path)
        out = cls(target, command, cls._prepare(target, overwrite, what))
        try:
            yield out
        except BaseException:
            out._finish("partial")
            raise
        out._finish(out.status if out.status == "complete" else "partial")

    @staticmethod
    def _prepare(path: Path, overwrite: bool, what: str) -> set[str]:
        """Create or check the folder; returns the files to keep (not written by relrl)."""
        _make_folder(path, what)
        _probe(path, what)
        present = _files(path)
        if not present:
            return set()
        earlier = _read_record(path)
        if not overwrite:
            by = (f"the outputs of `{earlier.get('command', 'relrl')}` "
                  f"({earlier.get('started', '?')})" if earlier else f"{len(present)} files")
            raise OutputError(f"{what} {path}: the folder is not empty (it holds {by}); "
                              "pass --overwrite to replace them, or choose a new folder")
        # the earlier run's files: those its record lists; a run killed before it finished
        # its record lists none, and then everything but what it found there is its own
        if not earlier:
            ours: set[str] = set()
        elif earlier.get("ended"):
            ours = set(earlier.get("files", [])) & present
        else:
            ours = present - set(earlier.get("kept", []))
        for name in sorted(ours):
            try:
                (path / name).unlink()
            except OSError as exc:
                raise OutputError(f"{what} {path}: cannot remove the earlier {name} "
                                  f"({_reason(exc)})") from None
        return present - ours

    def _record(self, ended: str | None = None) -> None:
        from relrl import __version__

        files = sorted(_files(self.path) - self._foreign) if ended else []
        write_json_atomic(self.path / MANIFEST, {
            "command": self.command, "relrl_version": __version__, "started": self._started,
            "ended": ended, "status": self.status, "files": files,
            "kept": sorted(self._foreign)})

    def _finish(self, status: str) -> None:
        self.status = status
        with contextlib.suppress(OutputError):  # the folder vanished: the error says more
            self._record(_dt.datetime.now().isoformat(timespec="seconds"))


def _read_record(path: Path) -> dict[str, Any]:
    try:
        data = json.loads((path / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}
