"""Point-cloud readers for text (XYZ, CSV), and what the cloud readers share: library errors
as one line, truncation hints, colours and classes by property name. LAS and LAZ are
:mod:`.las`, PCD :mod:`.pcd`, PLY :mod:`.ply`.

Library errors become one-line :class:`InputError` naming the file and what is wrong.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import numpy as np
from numpy.typing import NDArray

from astralis_des.errors import InputError
from astralis_des.importers.source import Cloud, ReadRequest, reader

_ENDS_EARLY = ("fill whole buffer", "unexpected end", "eof", "truncat", "unexpected length")
COLOR_NAMES = (("red", "green", "blue"), ("r", "g", "b"),
               ("diffuse_red", "diffuse_green", "diffuse_blue"))


def library_error(path: Path, what: str, exc: Exception) -> InputError:
    """A reading library's exception as one line: truncated, or not a file of that kind."""
    reason = " ".join(str(exc).split()) or type(exc).__name__
    if any(word in reason.lower() for word in _ENDS_EARLY):
        return InputError(f"truncated: the file ends before its data does ({reason})",
                          file=path)
    return InputError(f"not a readable {what} file ({reason})", file=path)


def partial_hint(held: int) -> str:
    """How to read a truncated file as far as it goes (nothing, when it holds nothing)."""
    return f"; pass --partial to import the {held:,} it holds" if held else ""


def truncated_note(held: int, announced: int, what: str) -> str:
    return (f"--partial: read the {held:,} whole {what} before the file ends, of the "
            f"{announced:,} its header announces")



def colors_from(columns: Mapping[str, np.ndarray], kinds: Mapping[str, str]
                ) -> NDArray[np.uint8] | None:
    """Colours from red, green and blue columns (lower-case names), as 8 bits."""
    for names in COLOR_NAMES:
        if all(n in columns for n in names):
            rgb = np.column_stack([columns[n] for n in names])
            return rgb8(rgb, unit=kinds.get(names[0], "").startswith("f"))
    return None


def rgb8(rgb: np.ndarray, unit: bool = False) -> NDArray[np.uint8]:
    """Colours as 8 bits: floats in [0, 1] (``unit``: the file stores floats) scaled up,
    16-bit ones scaled down."""
    values = np.nan_to_num(np.asarray(rgb, dtype=np.float64))
    top = float(values.max(initial=0.0))
    if unit and top <= 1.0:
        values = values * 255
    elif top > 255:  # 16-bit, as LAS stores it; 8-bit values in 16-bit fields stay as they are
        values = values / 257
    return np.clip(np.round(values), 0, 255).astype(np.uint8)


def classes_from(columns: Mapping[str, np.ndarray]) -> NDArray[np.uint8] | None:
    """ASPRS classes from a ``classification`` column (lower-case names), when there is one."""
    values = columns.get("classification")
    if values is None:
        return None
    return np.clip(np.nan_to_num(np.asarray(values, dtype=np.float64)), 0, 255).astype(np.uint8)


@reader("xyz", "csv", "txt", memory_per_byte=6.0)
def read_text(path: Path, request: ReadRequest) -> Cloud:
    """Rows of numbers separated by commas, semicolons or blanks; ``#`` starts a comment. A
    first row of names (``x,y,z,red,green,blue,classification``, any case) says which column
    is which; without one, the first three columns are x, y, z, and three more integer
    columns are RGB."""
    with path.open("rb") as raw:
        nul = raw.read(1 << 16).find(b"\0")
        if nul >= 0:
            raise InputError(f"not a text file (a NUL byte at offset {nul})", file=path)
        raw.seek(0)
        first, number, start = _first_row(raw)
        delimiter = delimiter_of(first)
        tokens = [t.strip().lstrip("/#").lower() for t in first.split(delimiter)]
        header = not all(is_number(t) for t in tokens)
        columns = {n: tokens.index(n) for n in tokens} if header else {}
        if header and not all(a in columns for a in "xyz"):
            found = ", ".join(tokens)
            raise InputError(f"the header row names no x, y and z columns (found: "
                             f"{found[:60] + '...' if len(found) > 60 else found})",
                             file=path, line=number)
        if not header:
            raw.seek(start)
        rows = read_rows(path, raw, delimiter=delimiter, width=None, rows=None,
                         skip=number if header else number - 1)
    data = rows.table
    if data.shape[1] < 3 or len(data) == 0:
        raise InputError("no rows of at least three numbers (x y z)", file=path)
    cloud = Cloud(data[:, [columns.get(a, i) for i, a in enumerate("xyz")]])
    if rows.cut is not None:
        if not request.partial:
            raise InputError("truncated: the file ends inside its last row"
                             + partial_hint(len(data)), file=path, line=rows.cut)
        cloud.notes.append(f"--partial: read the {len(data):,} whole rows before line "
                           f"{rows.cut:,}, where the file ends")
    _text_extras(cloud, data, columns, header)
    return cloud


def _text_extras(cloud: Cloud, data: np.ndarray, columns: dict[str, int], header: bool
                 ) -> None:
    rgb_names: list[str] = [n for n in ("red", "green", "blue") if n in columns] or \
        [n for n in ("r", "g", "b") if n in columns]
    if len(rgb_names) == 3:
        cloud.colors = rgb8(data[:, [columns[n] for n in rgb_names]])
    elif not header and data.shape[1] >= 6 and _is_rgb(data[:, 3:6]):
        cloud.colors = data[:, 3:6].astype(np.uint8)
    for name in ("classification", "class"):
        if name in columns:
            cloud.classification = data[:, columns[name]].astype(np.uint8)
            break


def _first_row(raw: BinaryIO) -> tuple[str, int, int]:
    """The first line that is not blank or a comment, its number and where it starts."""
    number = 0
    while True:
        start = raw.tell()
        line = raw.readline()
        number += 1
        text = line.decode("utf-8", "replace").strip()
        if not line or (text and not text.startswith("#")):
            return text, number, start


def delimiter_of(row: str) -> str | None:
    """The delimiter of a row of numbers: a semicolon, a comma, or blanks (None)."""
    return next((d for d in (";", ",") if d in row), None)


def is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _is_rgb(values: np.ndarray) -> bool:
    finite = values[np.isfinite(values).all(axis=1)]
    return bool(len(finite)) and bool(np.all((finite >= 0) & (finite <= 255) &
                                             (finite == np.round(finite))))


@dataclass
class Rows:
    """Rows of numbers read from text."""

    table: NDArray[np.float64]  # (rows, width)
    cut: int | None = None  # the line of a last row the file ends inside, left out


def read_rows(path: Path, raw: BinaryIO, *, delimiter: str | None, width: int | None,
              rows: int | None, skip: int) -> Rows:
    """At most ``rows`` rows of ``width`` numbers (None: as many as the first row) from
    ``raw``, which stands at line ``skip + 1`` of ``path``. A last row that the file ends
    inside is left out and its line reported; any other bad row is an error naming its line."""
    start = raw.tell()
    try:
        return Rows(_loadtxt(path, raw, delimiter, width, rows, skip))
    except ValueError as exc:
        bad = _first_bad_row(path, delimiter, skip, width)
        if bad is None:
            raise InputError(f"rows of numbers expected ({' '.join(str(exc).split())})",
                             file=path) from None
    if not bad.cut:
        raise InputError(bad.message, file=path, line=bad.line)
    raw.seek(start)
    return Rows(_loadtxt(path, raw, delimiter, width, bad.before, skip), cut=bad.line)


def _loadtxt(path: Path, raw: BinaryIO, delimiter: str | None, width: int | None,
             rows: int | None, skip: int) -> NDArray[np.float64]:
    if rows == 0:
        return np.zeros((0, width or 0))
    with warnings.catch_warnings():  # no rows at all: the caller says what that means
        warnings.filterwarnings("ignore", "loadtxt: input contained no data")
        table = np.loadtxt(raw, dtype=np.float64, delimiter=delimiter, ndmin=2, max_rows=rows)
    if len(table) == 0:
        return np.zeros((0, width or 0))
    if width is not None and table.shape[1] != width:
        raise InputError(f"{table.shape[1]} values a row where {width} are expected",
                         file=path, line=skip + 1)
    return table


@dataclass
class _BadRow:
    line: int
    message: str
    before: int  # good rows before it
    cut: bool  # the file ends inside it: a last line without a line end, short of values


def _first_bad_row(path: Path, delimiter: str | None, skip: int, width: int | None
                   ) -> _BadRow | None:
    """The first row after line ``skip`` that is not ``width`` numbers, found again line by
    line (only on failure)."""
    before = 0
    with path.open("r", encoding="utf-8", errors="replace") as text:
        for number, line in enumerate(text, start=1):
            body = line.split("#", 1)[0].strip()
            if number <= skip or not body:
                continue
            tokens = [t.strip() for t in body.split(delimiter)]
            width = width or len(tokens)
            bad = [t for t in tokens if not is_number(t)]
            if bad or len(tokens) != width:
                # a cut row: values missing, or only the last one cut inside its digits
                cut = not line.endswith("\n") and len(tokens) <= width and (
                    len(tokens) < width or bad == [tokens[-1]])
                message = f"'{bad[0]}' is not a number" if bad else \
                    f"{len(tokens)} values where {width} are expected"
                return _BadRow(number, message, before, cut)
            before += 1
    return None
