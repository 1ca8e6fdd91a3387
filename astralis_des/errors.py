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
    close = difflib.get_close_matches(word, options, n=5, cutoff=0.6)
    if close:  # of the close ones: the fewest edits, then two letters swapped, then difflib's
        best = min(close, key=lambda c: (edits(word, c), sorted(c) != sorted(word),
                                         close.index(c)))
        return f"did you mean '{best}'?"
    return "valid: " + ", ".join(options)


def edits(a: str, b: str) -> int:
    """Insertions, deletions, substitutions and swaps of neighbours from ``a`` to ``b``."""
    d = [[i + j if i * j == 0 else 0 for j in range(len(b) + 1)] for i in range(len(a) + 1)]
    for i in range(1, len(a) + 1):
        for j in range(1, len(b) + 1):
            cost = a[i - 1] != b[j - 1]
            d[i][j] = min(d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost)
            if i > 1 and j > 1 and a[i - 1] == b[j - 2] and a[i - 2] == b[j - 1]:
                d[i][j] = min(d[i][j], d[i - 2][j - 2] + 1)
    return d[-1][-1]
