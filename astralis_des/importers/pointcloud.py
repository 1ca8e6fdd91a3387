"""Point-cloud readers: PLY (trimesh: ASCII and binary; a PLY with faces is a mesh) and XYZ/CSV
text (numpy); LAS and LAZ are :mod:`.las`.

Library errors become one-line :class:`InputError` naming the file and what is wrong.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

import numpy as np

from astralis_des.errors import InputError
from astralis_des.importers.source import Cloud, Mesh, ReadRequest, reader

log = logging.getLogger(__name__)



_ENDS_EARLY = ("fill whole buffer", "unexpected end", "eof", "truncat", "unexpected length")


def library_error(path: Path, what: str, exc: Exception) -> InputError:
    """A reading library's exception as one line: truncated, or not a file of that kind."""
    reason = " ".join(str(exc).split()) or type(exc).__name__
    if any(word in reason.lower() for word in _ENDS_EARLY):
        return InputError(f"truncated: the file ends before its data does ({reason})",
                          file=path)
    return InputError(f"not a readable {what} file ({reason})", file=path)


@reader("ply", memory_per_byte=8.0)
def read_ply(path: Path, request: ReadRequest) -> Cloud | Mesh:
    """A PLY of vertices only is a cloud; with faces, a mesh."""
    import trimesh

    try:
        loaded: Any = trimesh.load(path, file_type="ply", process=False)
    except Exception as exc:
        raise library_error(path, "PLY", exc) from None
    faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64)
    vertices = np.asarray(loaded.vertices, dtype=np.float64).reshape(-1, 3)
    if len(faces):
        return Mesh(vertices, faces, watertight=bool(getattr(loaded, "is_watertight", False)))
    colors = getattr(loaded, "colors", None)
    rgb = np.asarray(colors)[:, :3].astype(np.uint8) \
        if colors is not None and len(colors) == len(vertices) else None
    return Cloud(vertices, colors=rgb)


@reader("xyz", "csv", "txt", memory_per_byte=6.0)
def read_text(path: Path, request: ReadRequest) -> Cloud:
    """Rows of numbers separated by commas or blanks; ``#`` starts a comment. A first row of
    names (``x,y,z,red,green,blue,classification``) says which column is which; without one,
    the first three columns are x, y, z, and three more integer columns are RGB."""
    with path.open("rb") as raw:
        nul = raw.read(1 << 16).find(b"\0")
    if nul >= 0:
        raise InputError(f"not a text file (a NUL byte at offset {nul})", file=path)
    with path.open("r", encoding="utf-8", errors="replace") as text:
        first = next((ln for ln in text if ln.strip() and not ln.lstrip().startswith("#")), "")
    delimiter = "," if "," in first else None
    tokens = [t.strip().lstrip("/#").lower() for t in first.split(delimiter)]
    header = not all(_is_number(t) for t in tokens)
    names = tokens if header else []
    columns = {n: names.index(n) for n in names}
    xyz_cols = [columns.get(a, i) for i, a in enumerate("xyz")]
    if header and not all(a in columns for a in "xyz"):
        found = ", ".join(names)
        raise InputError(f"the header row names no x, y and z columns (found: "
                         f"{found[:60] + '...' if len(found) > 60 else found})", file=path,
                         line=1)
    try:
        data = np.loadtxt(path, delimiter=delimiter, comments="#", skiprows=int(header),
                          ndmin=2, dtype=float)
    except ValueError:
        raise _bad_row(path, delimiter, int(header), len(tokens)) from None
    if data.shape[1] < 3 or len(data) == 0:
        raise InputError("no rows of at least three numbers (x y z)", file=path)
    cloud = Cloud(data[:, xyz_cols])
    rgb_names: list[str] = [n for n in ("red", "green", "blue") if n in columns] or \
        [n for n in ("r", "g", "b") if n in columns]
    if len(rgb_names) == 3:
        cloud.colors = np.clip(data[:, [columns[n] for n in rgb_names]], 0, 255).astype(np.uint8)
    elif not header and data.shape[1] >= 6 and _is_rgb(data[:, 3:6]):
        cloud.colors = data[:, 3:6].astype(np.uint8)
    for name in ("classification", "class"):
        if name in columns:
            cloud.classification = data[:, columns[name]].astype(np.uint8)
            break
    return cloud


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _is_rgb(values: np.ndarray) -> bool:
    finite = values[np.isfinite(values).all(axis=1)]
    return bool(len(finite)) and bool(np.all((finite >= 0) & (finite <= 255) &
                                             (finite == np.round(finite))))


def _bad_row(path: Path, delimiter: str | None, skip: int, width: int) -> InputError:
    """The first row numpy could not read, found again line by line (only on failure)."""
    with path.open("r", encoding="utf-8", errors="replace") as text:
        for number, line in enumerate(text, start=1):
            body = line.split("#", 1)[0].strip()
            if number <= skip or not body:
                continue
            tokens = body.split(delimiter)
            bad = next((t.strip() for t in tokens if not _is_number(t.strip())), None)
            if bad is not None:
                return InputError(f"'{bad}' is not a number", file=path, line=number)
            if len(tokens) != width:
                return InputError(f"{len(tokens)} values where the first row has {width}",
                                  file=path, line=number)
    return InputError("rows of numbers expected", file=path)


def spacing(xy: np.ndarray) -> float:
    """A cloud's mean horizontal point spacing: the square root of the area per point, the
    area being the 1 m cells that hold points."""
    if len(xy) == 0:
        return 0.0
    index = np.floor(xy - xy.min(axis=0)).astype(np.int64)
    cells = np.unique(index[:, 0] * (int(index[:, 1].max()) + 1) + index[:, 1])
    return math.sqrt(len(cells) / len(xy))
