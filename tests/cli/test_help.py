"""Every command and subcommand of ``relrl`` says what it does and shows an example in its
``--help``, and takes ``-v``/``-q`` after its own name (``relrl experiment sis -q``)."""

from __future__ import annotations

import argparse

import pytest

from relrl.cli import build_parser


def _parsers(parser: argparse.ArgumentParser, path: tuple[str, ...] = ()):
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        yield path, parser
    for action in subs:
        for name, child in action.choices.items():
            yield from _parsers(child, (*path, name))


LEAVES = list(_parsers(build_parser()))


def test_the_walk_finds_the_nested_commands() -> None:
    names = {" ".join(p) for p, _ in LEAVES}
    assert {"experiment sis", "experiment scaling", "experiment worlds", "head look",
            "check", "run", "report"} <= names


@pytest.mark.parametrize("path, parser", LEAVES, ids=[" ".join(p) for p, _ in LEAVES])
def test_every_command_shows_an_example_and_takes_quiet(path, parser) -> None:
    text = parser.format_help()
    assert "example" in text and "relrl " in text.split("example", 1)[1], text
    options = parser._option_string_actions
    assert "--quiet" in options or "-q" in options, " ".join(path)
