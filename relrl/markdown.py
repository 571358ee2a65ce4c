"""Text from data put into Markdown as text, never as markup.

A results.json, a run record or a file name is data: a task named ``<script>``, a command
holding ``|`` or a newline, or a folder named ``javascript:alert(1)`` must show as those
characters, not become HTML, a table's column, a new block or a link that runs code.
:func:`text` escapes a value for a paragraph or a table cell, :func:`code` shows it as a code
span when that is safe (else as escaped text), :func:`link` makes a relative link target;
:class:`Markdown` marks the few strings a renderer writes as markup on purpose.
"""

from __future__ import annotations

import re
from urllib.parse import quote

__all__ = ["Markdown", "code", "link", "text"]

#: characters that are markup in CommonMark or GitHub's Markdown (emphasis, code, links,
#: images, HTML and entities, tables, strike-through, headings, math), escaped with ``\``;
#: an underscore inside a word (``blocks_moves``) is no emphasis, and stays as it is.
_SPECIAL = re.compile(r"([\\`*\[\]<>&|~!#$]|(?<![^\W_])_|_(?![^\W_]))")
#: line breaks and other control characters: a value stays on its line (and its table row).
_CONTROL = re.compile(r"[\x00-\x1f\x7f\u2028\u2029]+")
#: what a code span may hold as it is: no backtick, no HTML-looking brackets, no table pipe.
_PLAIN_CODE = re.compile(r"[^`<>|]+")


class Markdown(str):
    """A string a renderer wrote as Markdown on purpose (kept as it is by a table)."""


def _one_line(value: object) -> str:
    return _CONTROL.sub(" ", str(value)).strip()


def text(value: object) -> Markdown:
    """``value`` as Markdown that shows exactly its characters, on one line."""
    if isinstance(value, Markdown):
        return value
    return Markdown(_SPECIAL.sub(r"\\\1", _one_line(value)))


def code(value: object) -> Markdown:
    """``value`` as a code span, or as escaped text when a code span could not hold it
    (a backtick, ``<``, ``>`` or ``|`` in it)."""
    line = _one_line(value)
    if _PLAIN_CODE.fullmatch(line):
        return Markdown(f"`{line}`")
    return text(line)


def link(path: str) -> str:
    """A relative path as a link target: every character that could make it a URL with a
    scheme (``javascript:``), leave the parentheses or carry HTML percent-encoded, and
    ``./`` in front so that it is read as a file beside the document."""
    target = quote(path, safe="/._-~")
    return target if target.startswith(("./", "../")) else f"./{target}"
