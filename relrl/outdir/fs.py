"""The file system under relrl's writer: folder descriptors, atomic writes, streams.

Everything here works from a descriptor of the folder a file goes into, so that a path is
resolved once: ``write_in`` (a whole file through a temporary file and a rename),
``new_file_in`` (a new, empty file for a stream), :class:`Stream` (a file written a record at
a time), ``subfolder`` (walking down without following a link) and :func:`deferred_signals`
(holding Ctrl-C while something must be written whole). The policy of output folders is in
:mod:`relrl.outdir.claim`; the public writer is :mod:`relrl.outdir`.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import signal
import stat
import threading
from collections.abc import Iterator
from pathlib import Path

from relrl.errors import OutputError

__all__ = ["LINK", "O_DIR", "O_NEW", "Stream", "deferred_signals", "file_mode", "is_special",
           "make_folder", "new_file_in", "open_folder", "reason", "refuse_link", "refuse_nul",
           "subfolder", "temp_name", "way_problem", "write_all", "write_in"]

#: open a folder (for a descriptor to work from).
O_DIR = os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC
#: create a new file, never through a link, never one that is there.
O_NEW = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC
#: what relrl says of a link in the way (after its path).
LINK = ("is a symbolic link; relrl writes nothing through a link (remove it, or choose another "
        "folder)")


def file_mode() -> int:
    """The mode of the files relrl writes: 0666 less the process umask (0644 usually)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return 0o666 & ~mask


def reason(exc: OSError) -> str:
    """The system's words for ``exc`` ("No space left on device")."""
    return exc.strerror or str(exc)


def is_special(path: Path) -> bool:
    """A device or a pipe (``/dev/null``, ``/dev/stdout``): written in place, never renamed."""
    try:
        mode = path.stat().st_mode
    except (OSError, ValueError):
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


def refuse_nul(path: str | Path, what: str) -> None:
    """Raise :class:`OutputError` when ``path`` holds a NUL (no file system takes one)."""
    if "\0" in str(path):
        raise OutputError(f"{what} {str(path)!r}: a path cannot hold a NUL character")


def make_folder(path: Path, what: str) -> None:
    """Create the folder ``path`` (and its parents) or say in one line why it cannot be."""
    refuse_nul(path, what)
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
        raise OutputError(f"{what} {path}: cannot create the folder ({reason(exc)})") \
            from None


def open_folder(path: Path, what: str) -> int:
    """A descriptor of the folder ``path`` (created when missing), checked writable."""
    make_folder(path, what)
    try:
        fd = os.open(path, O_DIR)
    except OSError as exc:
        raise OutputError(f"{what} {path}: cannot open the folder ({reason(exc)})") from None
    try:
        tmp = temp_name("probe")
        os.close(os.open(tmp, O_NEW, 0o600, dir_fd=fd))
        os.unlink(tmp, dir_fd=fd)
    except OSError as exc:
        os.close(fd)
        raise OutputError(f"{what} {path}: cannot write there ({reason(exc)})") from None
    return fd


def temp_name(name: str) -> str:
    """A fresh hidden temporary name beside ``name`` (``.NAME.1a2b3c4d.tmp``)."""
    return f".{name[:64]}.{secrets.token_hex(4)}.tmp"


def refuse_link(dir_fd: int, name: str, shown: Path) -> None:
    """Raise unless ``name`` in ``dir_fd`` is missing or a plain file (not a link, a folder)."""
    try:
        st = os.stat(name, dir_fd=dir_fd, follow_symlinks=False)
    except FileNotFoundError:
        return
    if stat.S_ISLNK(st.st_mode):
        raise OutputError(f"{shown} {LINK}")
    if stat.S_ISDIR(st.st_mode):
        raise OutputError(f"{shown} is a folder; cannot write a file there")


def write_all(fd: int, raw: bytes | memoryview) -> None:
    """Write every byte of ``raw`` to ``fd`` (a short write is continued)."""
    view = memoryview(raw)
    while view:
        view = view[os.write(fd, view):]


def write_in(dir_fd: int, name: str, raw: bytes, shown: Path) -> None:
    """Write ``raw`` as ``name`` in ``dir_fd``: a new temporary file, fsync, a rename. Raises
    the OSError of a failed write after removing the temporary file."""
    refuse_link(dir_fd, name, shown)
    tmp = temp_name(name)
    fd = os.open(tmp, O_NEW, 0o666, dir_fd=dir_fd)
    try:
        try:
            write_all(fd, raw)
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, name, src_dir_fd=dir_fd, dst_dir_fd=dir_fd)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp, dir_fd=dir_fd)
        raise


def new_file_in(dir_fd: int, name: str, shown: Path) -> int:
    """A new, empty file ``name`` in ``dir_fd`` open for writing (whatever was at the name is
    replaced by the rename, never written through)."""
    refuse_link(dir_fd, name, shown)
    tmp = temp_name(name)
    fd = os.open(tmp, O_NEW, 0o666, dir_fd=dir_fd)
    try:
        os.replace(tmp, name, src_dir_fd=dir_fd, dst_dir_fd=dir_fd)
    except BaseException:
        os.close(fd)
        with contextlib.suppress(OSError):
            os.unlink(tmp, dir_fd=dir_fd)
        raise
    return fd


class Stream:
    """A file written a whole record at a time (:func:`open_stream`): ``write`` then ``flush``
    and ``close`` as a text or binary file has them. A record that cannot be written whole
    (a full disk) is cut off and :class:`~relrl.errors.OutputError` raised, so the file ends
    at the last whole record; a file deleted under the writer is noticed at the next record.

    Attributes:
        name: the file's path, for messages.
    """

    def __init__(self, fd: int, name: Path, binary: bool = False) -> None:
        self.name = name
        self._fd: int | None = fd
        self._binary = binary
        self._size = 0
        self._lock = threading.Lock()

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` was called."""
        return self._fd is None

    def write(self, data: str | bytes) -> int:
        """Append one record (``str`` for a text stream, ``bytes`` for a binary one)."""
        if isinstance(data, str) == self._binary:
            raise TypeError(f"{self.name}: a {'binary' if self._binary else 'text'} stream "
                            f"takes {'bytes' if self._binary else 'str'}")
        raw = data if isinstance(data, bytes | bytearray) else data.encode("utf-8")
        with self._lock:
            if self._fd is None:
                raise ValueError(f"{self.name}: write to a closed stream")
            if os.fstat(self._fd).st_nlink == 0:
                raise OutputError(f"{self.name}: deleted while relrl was writing it (was the "
                                  "folder removed?)")
            try:
                write_all(self._fd, raw)
            except BaseException as exc:  # a full disk, or Ctrl-C mid-record: cut it off
                with contextlib.suppress(OSError):
                    os.ftruncate(self._fd, self._size)
                if isinstance(exc, OSError):
                    raise OutputError(f"cannot write {self.name}: {reason(exc)}") from None
                raise
            self._size += len(raw)
        return len(data)

    def flush(self) -> None:
        """Nothing to do: every record is written when :meth:`write` returns."""

    def close(self) -> None:
        """Close the file (safe twice)."""
        with self._lock:
            if self._fd is not None:
                fd, self._fd = self._fd, None
                with contextlib.suppress(OSError):
                    os.close(fd)

    def __enter__(self) -> Stream:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@contextlib.contextmanager
def subfolder(fd: int, parts: tuple[str, ...] | list[str]) -> Iterator[int | None]:
    """A descriptor of the subfolder ``parts`` of ``fd`` walked without following a link
    (``None`` when a part is a link, a file or missing)."""
    opened: list[int] = []
    try:
        for part in parts:
            try:
                fd = os.open(part, O_DIR | os.O_NOFOLLOW, dir_fd=fd)
            except OSError:
                fd = -1
                break
            opened.append(fd)
        yield fd if fd >= 0 else None
    finally:
        for f in opened:
            os.close(f)


def way_problem(dir_fd: int, rel: str) -> str | None:
    """What stops ``rel`` (``name``, ``sub/name``, or a folder ``name/``) from being written
    under ``dir_fd`` without following a link: a part that is a link, a file where a folder
    must be, a folder where the file goes, a name longer than the file system takes. None
    when nothing does (missing folders are created by the writer)."""
    longest = os.fpathconf(dir_fd, "PC_NAME_MAX")
    parts = rel.rstrip("/").split("/")
    for i, part in enumerate(parts):
        here = "/".join(parts[:i + 1])
        if len(os.fsencode(part)) > longest:
            return f"cannot write {rel[:60]}...: a file name here has at most {longest} bytes"
        with subfolder(dir_fd, parts[:i]) as sub:
            if sub is None:
                return None  # a folder above is missing: the writer creates it
            try:
                mode = os.stat(part, dir_fd=sub, follow_symlinks=False).st_mode
            except FileNotFoundError:
                return None
        if stat.S_ISLNK(mode):
            return f"{here} {LINK}"
        last = i == len(parts) - 1
        if not last and not stat.S_ISDIR(mode):
            return f"{here} is a file; {rel} cannot be written under it"
        if last and stat.S_ISDIR(mode) and not rel.endswith("/"):
            return f"{here} is a folder; {rel} cannot be written there"
    return None


@contextlib.contextmanager
def deferred_signals() -> Iterator[None]:
    """Hold SIGINT, SIGTERM and SIGHUP while the block writes what must not be cut in half;
    afterwards each one held is delivered again to the handler that was there before.
    Outside the main thread the block runs unchanged."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    sigs = [s for s in (signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGHUP", None))
            if s is not None]
    old = {s: signal.signal(s, lambda signum, frame: held.append(signum)) for s in sigs}
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        for s in dict.fromkeys(held):
            signal.raise_signal(s)


