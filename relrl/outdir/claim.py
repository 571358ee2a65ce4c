"""Output folders claimed by one command: the lock, the journal, the record, --overwrite.

See :mod:`relrl.outdir` for the policy. A claim holds a descriptor of its folder from start to
end: the lock is an ``flock`` on it, and every file the command writes into the folder is
reached from it without following a link (:meth:`OutDir.write`, :meth:`OutDir.stream`).
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import errno
import fcntl
import json
import os
import socket
import stat
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path, PurePosixPath
from typing import Any

from relrl.errors import OutputError
from relrl.outdir.fs import (
    LINK,
    O_DIR,
    Stream,
    deferred_signals,
    make_folder,
    new_file_in,
    open_folder,
    reason,
    refuse_nul,
    subfolder,
    way_problem,
    write_all,
    write_in,
)

__all__ = ["JOURNAL", "MANIFEST", "SPARE", "OutDir", "claim_of", "timestamped"]

#: the record of the run that wrote a folder.
MANIFEST = ".relrl-run.json"
#: the names a running command has written (one JSON string a line), for a later --overwrite.
JOURNAL = ".relrl-run.files"
#: space held back for the last writes of a command.
SPARE = ".relrl-run.spare"
SPARE_BYTES = 64 * 1024
#: bytes the first record takes (padding), so that the last one fits on a full disk.
RECORD_ROOM = 16 * 1024
_INTERNAL = (MANIFEST, JOURNAL, SPARE)

_CLAIMS: list[OutDir] = []
_CLAIMS_LOCK = threading.Lock()


def claim_of(path: Path) -> tuple[OutDir, list[str]] | None:
    """The claimed folder ``path`` lies in, and the path's parts inside it."""
    target = Path(os.path.abspath(path))
    with _CLAIMS_LOCK:
        claims = list(_CLAIMS)
    for out in reversed(claims):
        if target.is_relative_to(out.absolute) and target != out.absolute:
            return out, list(target.relative_to(out.absolute).parts)
    return None


def _parts(rel: str | Path, shown: str) -> list[str]:
    text = str(rel)
    refuse_nul(text, shown)
    parts = PurePosixPath(text).parts
    if not parts or PurePosixPath(text).is_absolute() or any(p in (".", "..") for p in parts):
        raise OutputError(f"{shown}: not a file name inside the output folder")
    return list(parts)


class OutDir:
    """An output folder claimed (and locked) by one command (see the module's policy).

    Attributes:
        path: the folder, as given.
        status: ``complete`` once the caller says so; left ``partial`` otherwise.
    """

    def __init__(self, path: Path, command: str, fd: int, foreign: set[str]) -> None:
        self.path = path
        self.command = command
        self.status = "running"
        self.absolute = Path(os.path.abspath(path))
        self._fd = fd
        self._foreign = foreign
        self._written: set[str] = set()
        self._lock = threading.RLock()
        self._spare = False
        self._started = _dt.datetime.now().isoformat(timespec="seconds")
        self._hold_space()
        try:
            self._journal = Stream(new_file_in(fd, JOURNAL, path / JOURNAL), path / JOURNAL)
            self._record()
        except OSError as exc:
            _remove_internal(fd)
            raise OutputError(f"{path}: cannot write there ({reason(exc)})") from None

    @property
    def written(self) -> list[str]:
        """The files this command wrote into the folder so far (``name`` or ``sub/name``),
        sorted; folders are left out."""
        with self._lock:
            return sorted(n for n in self._written if not n.endswith("/"))

    @classmethod
    @contextlib.contextmanager
    def claim(cls, path: str | Path | None, *, command: str, overwrite: bool = False,
              default: str | None = None, what: str = "--out",
              outputs: Iterable[str] = ()) -> Iterator[OutDir]:
        """Claim and lock an output folder for the block; the record is finished on exit.

        Args:
            path: the folder (``None``: a fresh :func:`timestamped` folder from ``default``).
            command: the command line, for the record.
            overwrite: replace an earlier run's files instead of refusing a non-empty folder.
            default: the base name of the timestamped folder when ``path`` is ``None``.
            what: the option, for messages.
            outputs: the files (``name``, ``sub/name``) and folders (``name/``) the command
                will write: checked now, before the work, for a link or a file in the way
                and for names the file system cannot hold.

        Raises:
            OutputError: the folder is not usable, is being written by another command, is
                not empty without ``overwrite``, or cannot take one of ``outputs``.
        """
        if path is None:
            if default is None:
                raise ValueError("OutDir.claim needs a path or a default")
            target = _fresh_folder(default, what)
        else:
            target = Path(path)
        fd = open_folder(target, what)
        try:
            _lock(fd, target, what)
            foreign = _prepare(fd, target, overwrite, what, outputs)
            out = cls(target, command, fd, foreign)
        except BaseException:
            os.close(fd)
            raise
        with _CLAIMS_LOCK:
            _CLAIMS.append(out)
        try:
            yield out
        except BaseException:
            out._finish("partial")
            raise
        out._finish(out.status if out.status == "complete" else "partial")

    # -- writing ------------------------------------------------------------------------------

    def write(self, rel: str | Path, data: bytes | str, *, spare: bool = True) -> Path:
        """Write the file ``rel`` (a path inside the folder) whole and atomically.

        Args:
            rel: the file, relative to the folder; missing subfolders are created.
            data: its content.
            spare: on a full disk, give back the space held back and try once more;
                frames and other bulk files pass ``False``.

        Raises:
            OutputError: a link or a file in the way, a full disk, the folder gone.
        """
        raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
        parts = _parts(rel, str(self.path / str(rel)))
        shown = self.path.joinpath(*parts)
        with self._folder(parts[:-1], shown) as dir_fd:
            self._note_name("/".join(parts), shown)
            try:
                write_in(dir_fd, parts[-1], raw, shown)
            except OSError as exc:
                if exc.errno == errno.ENOSPC and spare and self._give_back():
                    try:
                        write_in(dir_fd, parts[-1], raw, shown)
                        return shown
                    except OSError as again:
                        exc = again
                raise self._error(shown, exc) from None
        return shown

    def stream(self, rel: str | Path, *, binary: bool = False) -> Stream:
        """A new :class:`Stream` ``rel`` inside the folder (see :func:`open_stream`)."""
        parts = _parts(rel, str(self.path / str(rel)))
        shown = self.path.joinpath(*parts)
        with self._folder(parts[:-1], shown) as dir_fd:
            self._note_name("/".join(parts), shown)
            try:
                fd = new_file_in(dir_fd, parts[-1], shown)
            except OSError as exc:
                raise self._error(shown, exc) from None
        return Stream(fd, shown, binary)

    @contextlib.contextmanager
    def _folder(self, parts: list[str], shown: Path) -> Iterator[int]:
        """A descriptor of the subfolder ``parts`` (created when missing; never a link)."""
        fd = self._fd
        try:
            for i, part in enumerate(parts):
                sub = "/".join(parts[:i + 1])
                try:
                    if not _there(fd, part):
                        self._note_name(sub + "/", shown)  # made by this command
                        with contextlib.suppress(FileExistsError):
                            os.mkdir(part, dir_fd=fd)
                    st = os.stat(part, dir_fd=fd, follow_symlinks=False)
                    if stat.S_ISLNK(st.st_mode):
                        raise OutputError(f"{self.path / sub} {LINK}")
                    if not stat.S_ISDIR(st.st_mode):
                        raise OutputError(f"{self.path / sub} is a file, not a folder; "
                                          f"cannot write {shown}")
                    nfd = os.open(part, O_DIR | os.O_NOFOLLOW, dir_fd=fd)
                except OSError as exc:
                    raise self._error(shown, exc) from None
                if fd != self._fd:
                    os.close(fd)
                fd = nfd
            yield fd
        finally:
            if fd != self._fd:
                os.close(fd)

    def _error(self, shown: Path, exc: OSError) -> OutputError:
        if self._gone():
            return OutputError(f"{self.path}: the folder was deleted while relrl was writing "
                               f"into it; {shown.name} was not written")
        return OutputError(f"cannot write {shown}: {reason(exc)}")

    def _gone(self) -> bool:
        try:
            return os.fstat(self._fd).st_nlink == 0
        except OSError:
            return True

    def _note_name(self, name: str, shown: Path) -> None:
        """Journal ``name`` (a folder ends in ``/``) before it is created: a later
        --overwrite deletes only what the journal or the record names."""
        with self._lock:
            if name in self._written:
                return
            try:
                self._journal.write(json.dumps(name) + "\n")
            except OutputError:
                raise OutputError(f"cannot write {shown}: "
                                  + ("the folder was deleted" if self._gone() else
                                     f"cannot note it in {JOURNAL} (is the disk full?)")) \
                    from None
            self._written.add(name)

    # -- the space held back ------------------------------------------------------------------

    def _hold_space(self) -> None:
        try:
            fd = new_file_in(self._fd, SPARE, self.path / SPARE)
            try:
                write_all(fd, bytes(SPARE_BYTES))
                os.fsync(fd)
            finally:
                os.close(fd)
        except OSError as exc:
            with contextlib.suppress(OSError):
                os.unlink(SPARE, dir_fd=self._fd)
            raise OutputError(f"{self.path}: cannot write there ({reason(exc)})") from None
        self._spare = True

    def _give_back(self) -> bool:
        """Delete the space held back; whether there was any."""
        with self._lock:
            if not self._spare:
                return False
            self._spare = False
            with contextlib.suppress(OSError):
                os.unlink(SPARE, dir_fd=self._fd)
            return True

    # -- the record ---------------------------------------------------------------------------

    def _record(self, ended: str | None = None) -> bool:
        """Write the record (atomic; the first one padded to :data:`RECORD_ROOM` bytes so
        that the last one has room on a full disk). Returns whether it lists the files
        (when it had to be written in that room without them, the journal stays)."""
        from relrl import __version__

        files = sorted(n for n in self._written if not n.endswith("/")
                       and _exists(self._fd, n)) if ended else []
        folders = sorted(n[:-1] for n in self._written if n.endswith("/")) if ended else []
        data = {"command": self.command, "relrl_version": __version__,
                "started": self._started, "ended": ended, "status": self.status,
                "files": files, "folders": folders, "kept": sorted(self._foreign - set(files)),
                "pid": os.getpid(), "host": socket.gethostname()}
        raw = (json.dumps(data, indent=1, sort_keys=True) + "\n").encode("utf-8")
        if ended is None:
            raw += b" " * (RECORD_ROOM - len(raw)) + b"\n" if len(raw) < RECORD_ROOM else b""
        try:
            write_in(self._fd, MANIFEST, raw, self.path / MANIFEST)
            return True
        except OSError as exc:
            if exc.errno != errno.ENOSPC or ended is None:
                raise
        # a full disk: rewrite the record in the room the first one took (not atomic, but a
        # torn record only makes a later --overwrite keep every file)
        listed = True
        if len(raw) > self._room():
            data.update(files=[], folders=[], journal=JOURNAL)
            raw, listed = (json.dumps(data, indent=1, sort_keys=True) + "\n").encode(), False
        fd = os.open(MANIFEST, os.O_WRONLY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=self._fd)
        try:
            os.pwrite(fd, raw, 0)
            os.ftruncate(fd, len(raw))
            os.fsync(fd)
        finally:
            os.close(fd)
        return listed

    def _room(self) -> int:
        try:
            return os.stat(MANIFEST, dir_fd=self._fd, follow_symlinks=False).st_size
        except OSError:
            return 0

    def _finish(self, status: str) -> None:
        self.status = status
        with deferred_signals():
            self._give_back()
            with contextlib.suppress(OSError, OutputError):  # a vanished folder says more
                listed = self._record(_dt.datetime.now().isoformat(timespec="seconds"))
                self._journal.close()
                if listed:
                    os.unlink(JOURNAL, dir_fd=self._fd)
            self._journal.close()
            with _CLAIMS_LOCK:
                if self in _CLAIMS:
                    _CLAIMS.remove(self)
            os.close(self._fd)  # lets go of the lock


def _there(dir_fd: int, name: str) -> bool:
    """Whether anything (a link included) is at ``name`` in ``dir_fd``."""
    try:
        os.stat(name, dir_fd=dir_fd, follow_symlinks=False)
    except FileNotFoundError:
        return False
    return True


def _exists(dir_fd: int, rel: str) -> bool:
    """Whether ``rel`` under ``dir_fd`` is a regular file (reached through no link)."""
    *folder, base = rel.split("/")
    with subfolder(dir_fd, folder) as sub:
        try:
            return sub is not None and stat.S_ISREG(
                os.stat(base, dir_fd=sub, follow_symlinks=False).st_mode)
        except OSError:
            return False


def _check_outputs(fd: int, path: Path, outputs: Iterable[str], what: str) -> None:
    """Refuse, before the work, an output that is a link, lies under a link or a file, or
    has a name longer than the folder's file system takes."""
    for name in outputs:
        _parts(name, f"{what} {path}: {name!r}")
        problem = way_problem(fd, name)
        if problem:
            raise OutputError(f"{what} {path}: {problem}")


def _lock(fd: int, path: Path, what: str) -> None:
    """Lock the folder for this command; refuse when another command holds it."""
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        rec = _read_record(fd)
        who = (f"`{rec.get('command', 'relrl')}` (process {rec.get('pid', '?')}, started "
               f"{rec.get('started', '?')})" if rec else "another relrl command")
        raise OutputError(f"{what} {path}: {who} is writing into this folder now; wait for "
                          "it to end or choose another folder") from None
    except OSError as exc:  # a file system without locks: say so rather than race
        raise OutputError(f"{what} {path}: cannot lock the folder ({reason(exc)})") from None


def _present(fd: int, prefix: str = "") -> set[str]:
    """Every file (and link) under the folder, without following links; relrl's own
    bookkeeping files are left out."""
    found: set[str] = set()
    with os.scandir(fd) as entries:
        for entry in entries:
            name = prefix + entry.name
            if entry.is_dir(follow_symlinks=False):
                sub = os.open(entry.name, O_DIR | os.O_NOFOLLOW, dir_fd=fd)
                try:
                    found |= _present(sub, name + "/")
                finally:
                    os.close(sub)
            elif prefix or entry.name not in _INTERNAL:
                found.add(name)
    return found


def _prepare(fd: int, path: Path, overwrite: bool, what: str,
             outputs: Iterable[str]) -> set[str]:
    """Check the folder and the outputs to come; delete an earlier run's files under
    ``overwrite``. Returns the files that stay (relrl did not write them)."""
    present = _present(fd)
    earlier = _read_record(fd)
    if not present:
        _check_outputs(fd, path, outputs, what)
        _remove_internal(fd)
        return set()
    if not overwrite:
        by = (f"the outputs of `{earlier.get('command', 'relrl')}` "
              f"({earlier.get('started', '?')})" if earlier else f"{len(present)} files")
        raise OutputError(f"{what} {path}: the folder is not empty (it holds {by}); "
                          "pass --overwrite to replace them, or choose a new folder")
    _check_outputs(fd, path, outputs, what)
    if earlier.get("ended") and not earlier.get("journal"):
        ours = {n for n in earlier.get("files", []) if isinstance(n, str)} & present
        made = [n for n in earlier.get("folders", []) if isinstance(n, str)]
    else:  # killed before its record was finished (or out of room): the journal lists
        journal = _read_journal(fd)
        ours = {n for n in journal if not n.endswith("/")} & present
        made = [n[:-1] for n in journal if n.endswith("/")]
    try:
        _remove(fd, ours)
    except OSError as exc:
        raise OutputError(f"{what} {path}: cannot remove the earlier run's files "
                          f"({reason(exc)})") from None
    for folder in sorted(made, key=lambda n: -n.count("/")):  # deepest first; only if empty
        if not _plain(folder):
            continue  # a record someone edited: never leave the folder
        *above, base = folder.split("/")
        with subfolder(fd, above) as sub, contextlib.suppress(OSError):
            if sub is not None:
                os.rmdir(base, dir_fd=sub)
    _remove_internal(fd)
    return present - ours


def _plain(name: str) -> bool:
    """A relative path of plain names (no ``..``, ``.``, empty part or NUL)."""
    parts = name.split("/")
    return "\0" not in name and all(p not in ("", ".", "..") for p in parts)


def _remove(fd: int, names: set[str]) -> None:
    """Delete ``names`` (paths under ``fd``) with the temporary files a killed write left of
    them, never through a link: a path through a link is left alone."""
    by_folder: dict[tuple[str, ...], set[str]] = {}
    for name in names:
        *folder, base = name.split("/")
        by_folder.setdefault(tuple(folder), set()).add(base)
    for folder, bases in by_folder.items():
        with subfolder(fd, folder) as sub:
            if sub is None:
                continue  # a link or gone: not the earlier run's any more
            for base in sorted(bases):
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(base, dir_fd=sub)
            stems = {f".{b[:64]}." for b in bases}
            for entry in os.listdir(sub):
                if entry.endswith(".tmp") and entry[:-13] + "." in stems \
                        and len(entry) > 13 and entry[-13] == ".":
                    with contextlib.suppress(OSError):
                        os.unlink(entry, dir_fd=sub)


def _remove_internal(fd: int) -> None:
    for name in (JOURNAL, SPARE):
        with contextlib.suppress(OSError):
            os.unlink(name, dir_fd=fd)


def _read_record(fd: int) -> dict[str, Any]:
    try:
        rfd = os.open(MANIFEST, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=fd)
        with os.fdopen(rfd, "rb") as fh:
            data = json.loads(fh.read(1 << 22).decode("utf-8"))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def _read_journal(fd: int) -> list[str]:
    try:
        jfd = os.open(JOURNAL, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=fd)
        with os.fdopen(jfd, "rb") as fh:
            lines = fh.read().decode("utf-8", "replace").splitlines()
    except OSError:
        return []
    names = []
    for line in lines:
        try:
            name = json.loads(line)
        except ValueError:
            continue  # the last line of a journal cut off by a crash
        if isinstance(name, str):
            names.append(name)
    return names


def timestamped(base: str | Path) -> Path:
    """A folder name ``BASE-YYYYMMDD-HHMMSS`` that does not exist yet (``-2``... if taken)."""
    stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    first = Path(f"{base}-{stamp}")
    candidate, n = first, 1
    while candidate.exists() or candidate.is_symlink():
        n += 1
        candidate = Path(f"{first}-{n}")
    return candidate


def _fresh_folder(base: str, what: str) -> Path:
    """Create a new :func:`timestamped` folder (two commands in one second get two)."""
    make_folder(Path(base).parent, what)
    for _ in range(1000):
        candidate = timestamped(base)
        try:
            candidate.mkdir()
            return candidate
        except FileExistsError:
            continue
        except OSError as exc:
            raise OutputError(f"{what} {candidate}: cannot create the folder "
                              f"({reason(exc)})") from None
    raise OutputError(f"{what} {base}-*: no free folder name")


