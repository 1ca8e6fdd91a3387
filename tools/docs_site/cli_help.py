"""A MkDocs hook (``mkdocs.yml``'s ``hooks``): the command line reference shows each command's
``--help`` as the parser gives it, so the page cannot drift from the code.

A page that holds the line ``<!-- astralis --help -->`` gets, in its place, a section per
command and subcommand (``astralis run``, ``astralis world import``, ...), each with its help.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

MARK = "<!-- astralis --help -->"
ROOT = Path(__file__).resolve().parents[2]
WIDTH = "96"  # columns of the help text: the page's code blocks, not the terminal's


def on_page_markdown(markdown: str, **_: Any) -> str:
    if MARK not in markdown:
        return markdown
    return markdown.replace(MARK, "\n".join(_sections()))


def _sections() -> Iterator[str]:
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from astralis_des.cli import _parser

    before = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = WIDTH
    try:
        for parser in _commands(_parser()):
            yield f"### `{parser.prog}`\n\n```text\n{parser.format_help().rstrip()}\n```\n"
    finally:
        if before is None:
            os.environ.pop("COLUMNS", None)
        else:
            os.environ["COLUMNS"] = before


def _commands(parser: argparse.ArgumentParser) -> Iterator[argparse.ArgumentParser]:
    """Every subcommand's parser, depth first, in the order the parser declares them."""
    for action in parser._actions:  # argparse has no public list of its subparsers
        if isinstance(action, argparse._SubParsersAction):
            for sub in dict.fromkeys(action.choices.values()):
                yield sub
                yield from _commands(sub)
