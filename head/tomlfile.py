"""TOML files a user gives (calibrations here, episode scripts in relrl), read with bounds.

``tomllib`` reads a whole file and recurses once per level of nested arrays and inline
tables, so a device such as ``/dev/zero`` exhausts memory and ``x = [[[[...]]]]`` 3,000 deep
ends in a ``RecursionError``. :func:`read_limited` reads only a regular file of at most
:data:`MAX_BYTES`; :func:`too_deep` finds, before parsing, the line where nesting passes
:data:`MAX_NESTING` (a real file nests two or three levels).

Example:
    >>> too_deep("x = [[1], {a = [2]}]\\n") is None
    True
    >>> too_deep("\\nx = " + "[" * 40 + "]" * 40)
    2
"""

from __future__ import annotations

import errno
import os
import re
import stat

__all__ = ["MAX_BYTES", "MAX_NESTING", "read_limited", "too_deep"]

#: the largest TOML file read (bytes): far above any calibration or episode script.
MAX_BYTES = 16 * 1024 * 1024
#: the deepest nesting of arrays and inline tables in one another (tables' headers count).
MAX_NESTING = 32

#: what can hold a bracket that does not nest: comments and the four kinds of strings
#: (a multi-line string may end with up to two more quotes); then the brackets themselves.
_TOKEN = re.compile("|".join([
    r"#[^\n]*",                             # a comment
    r'"""(?:\\.|[^\\])*?"""(?:"{0,2})',      # a multi-line basic string
    r"'''.*?'''(?:'{0,2})",                # a multi-line literal string
    r'"(?:\\.|[^"\\\n])*"',                  # a basic string
    r"'[^'\n]*'",                           # a literal string
    r"[\[\]{}]",                            # a bracket
]), re.DOTALL)


def read_limited(path: str | os.PathLike, limit: int = MAX_BYTES) -> bytes:
    """The bytes of the regular file at ``path``, at most ``limit`` of them.

    Raises:
        FileNotFoundError: no such file.
        IsADirectoryError: ``path`` is a folder.
        OSError: not a regular file (a device, a pipe, a socket: ``strerror`` says so),
            larger than ``limit``, a name with a NUL character, or unreadable.
    """
    if "\0" in os.fspath(path):
        raise OSError(errno.EINVAL, "a file name cannot hold a NUL character", repr(path))
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)  # a pipe must not block the open
    try:
        mode = os.fstat(fd).st_mode
        if stat.S_ISDIR(mode):
            raise IsADirectoryError(errno.EISDIR, "is a folder, not a file", str(path))
        if not stat.S_ISREG(mode):
            raise OSError(errno.EINVAL, "not a regular file: a device, a pipe or a socket",
                          str(path))
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(limit + 1)
    finally:
        os.close(fd)
    if len(data) > limit:
        size = f"{limit // (1024 * 1024)} MB" if limit >= 1024 * 1024 else f"{limit} bytes"
        raise OSError(errno.EFBIG, f"larger than {size}", str(path))
    return data


def too_deep(text: str, limit: int = MAX_NESTING) -> int | None:
    """The 1-based line where arrays and inline tables of ``text`` nest more than
    ``limit`` deep, or None (brackets in strings and comments do not count)."""
    depth = 0
    for m in _TOKEN.finditer(text):
        token = m.group()
        if token in "[{":
            depth += 1
            if depth > limit:
                return text.count("\n", 0, m.start()) + 1
        elif token in "]}":
            depth = max(0, depth - 1)
    return None

