"""Files relrl reads as Prolog text (domains, worlds, policies) are UTF-8, comments too.

Prolog's reader warns about a byte that is not UTF-8 in a term, with the line it reached
(one or more lines after the byte), and passes one in a comment silently. :func:`not_utf8`
finds the first such byte and its line before Prolog reads the file, so the message can
name the file and the right line, once.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["MAX_CHECKED", "not_utf8"]

#: the largest file checked (the readers refuse larger policies by their size; a domain of
#: this size is no hand-written file).
MAX_CHECKED = 64 << 20


def not_utf8(path: str | Path) -> tuple[int, str] | None:
    """``(line, "byte 0xNN is not UTF-8 ...")`` for the first byte of the file at ``path``
    that is not UTF-8; ``None`` when it is UTF-8 text, or is no regular file that can be
    read (its reader says what it is)."""
    path = Path(path)
    try:
        if not path.is_file() or path.stat().st_size > MAX_CHECKED:
            return None
        data = path.read_bytes()
    except OSError:
        return None
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        return line, (f"byte 0x{data[exc.start]:02x} is not UTF-8 (relrl reads Prolog files "
                      "as UTF-8 text; save it as UTF-8)")
    return None
