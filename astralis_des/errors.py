"""Errors raised for bad input: each names the file, the line and the key."""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from pathlib import Path


class InputError(Exception):
    """Bad input at the edge: a file that cannot be used as it is.

    ``str(error)`` is one line: ``FILE:LINE: KEY: MESSAGE``.
    """

    def __init__(
        self, message: str, *, file: str | Path | None = None, line: int | None = None,
        key: str | None = None,
    ) -> None:
        self.message = message
        self.file = str(file) if file is not None else None
        self.line = line
        self.key = key
        super().__init__(self.one_line())

    def one_line(self) -> str:
        place = self.file or ""
        if self.line is not None:
            place += f":{self.line}"
        text = f"{place}: " if place else ""
        if self.key:
            text += f"{self.key}: "
        return text + " ".join(self.message.split())


def suggest(word: str, choices: Iterable[str]) -> str:
    """A ``did you mean`` hint for an unknown word, or the list of valid words."""
    options = sorted(set(choices))
    close = difflib.get_close_matches(word, options, n=1, cutoff=0.6)
    if close:
        return f"did you mean '{close[0]}'?"
    return "valid: " + ", ".join(options)
