"""PCD (the Point Cloud Library's format): ascii, binary and binary_compressed.

None of the project's libraries reads PCD, so this is a small reader on numpy: the text header
says the fields, their sizes, types and counts; the points follow as text rows (any of blank,
comma or semicolon between values), as packed records, or LZF-compressed one field after
another (binary_compressed). Field names are matched in any case (PDAL writes ``X Y Z``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import numpy as np
from numpy.typing import NDArray

from astralis_des.errors import InputError
from astralis_des.importers.pointcloud import (
    classes_from,
    colors_from,
    delimiter_of,
    is_number,
    partial_hint,
    read_rows,
    truncated_note,
)
from astralis_des.importers.source import Cloud, ReadRequest, check_memory, reader

HEADER_KEYS = ("VERSION", "FIELDS", "COLUMNS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT",
               "VIEWPOINT", "POINTS", "DATA")  # COLUMNS: FIELDS before PCD v0.6
TYPES = {("F", 4): "f4", ("F", 8): "f8", ("U", 1): "u1", ("U", 2): "u2", ("U", 4): "u4",
         ("U", 8): "u8", ("I", 1): "i1", ("I", 2): "i2", ("I", 4): "i4", ("I", 8): "i8"}
DATA_KINDS = ("ascii", "binary", "binary_compressed")
MAX_HEADER_LINES = 1000
Columns = dict[str, NDArray]


@dataclass
class Field:
    name: str  # lower case; "_" is padding
    dtype: np.dtype  # one value, little-endian
    count: int  # values a point

    @property
    def size(self) -> int:
        return self.dtype.itemsize * self.count


@dataclass
class Header:
    fields: list[Field]
    points: int
    data: str  # one of DATA_KINDS
    line: int  # the DATA line: the points start after it


@reader("pcd", memory_per_byte=6.0)
def read_pcd(path: Path, request: ReadRequest) -> Cloud:
    with path.open("rb") as raw:
        header = _header(path, raw)
        if header.data == "binary_compressed":
            columns = _compressed(path, raw, header)
        else:
            read = _ascii if header.data == "ascii" else _binary
            columns = read(path, raw, header, request.partial)
    cloud = _cloud(columns, header)
    if len(cloud.xyz) < header.points:
        cloud.notes.append(truncated_note(len(cloud.xyz), header.points, "points"))
    return cloud


def _header(path: Path, raw: BinaryIO) -> Header:
    keys: dict[str, tuple[list[str], int]] = {}
    last = 1
    for number in range(1, MAX_HEADER_LINES + 1):
        line = raw.readline(1 << 16)
        if not line:
            break
        text = line.decode("ascii", "replace").strip()
        if not text or text.startswith("#"):
            continue
        key, *values = text.split()
        if key.upper() not in HEADER_KEYS:
            raise _not_a_key(path, number, key, bool(keys))
        keys[key.upper()] = (values, number)
        last = number
        if key.upper() == "DATA":
            return _parse(path, keys, number)
    raise InputError("the header ends without a DATA line (DATA ascii, binary or "
                     "binary_compressed)", file=path, line=last)


def _not_a_key(path: Path, number: int, key: str, after_keys: bool) -> InputError:
    number_row = is_number(key.replace(";", ",").split(",")[0])
    if number_row and not after_keys:
        return InputError("no PCD header: the file starts with rows of numbers; to read them "
                          "as x y z, pass --format xyz", file=path, line=number)
    if number_row:
        return InputError("the header ends without a DATA line before the points; add one "
                          "(DATA ascii)", file=path, line=number)
    shown = repr(key[:20] + ("..." if len(key) > 20 else ""))
    return InputError(f"{shown} is not a PCD header key: not a PCD file", file=path,
                      line=number)


def _parse(path: Path, keys: dict[str, tuple[list[str], int]], line: int) -> Header:
    names, names_line = keys.get("FIELDS") or keys.get("COLUMNS") or ([], line)
    if not names:
        raise InputError("the header has no FIELDS", file=path, line=line)
    data = keys["DATA"][0][0].lower() if keys["DATA"][0] else ""
    if data not in DATA_KINDS:
        raise InputError(f"DATA '{data}' is not one of: {', '.join(DATA_KINDS)}", file=path,
                         line=line)
    return Header(_fields(path, keys, names, names_line), _points(path, keys, line), data, line)


def _fields(path: Path, keys: dict[str, tuple[list[str], int]], names: list[str],
            names_line: int) -> list[Field]:
    # Before PCD v0.7 SIZE, TYPE and COUNT could be left out: 4-byte floats, one each.
    sizes, sizes_line = keys.get("SIZE", (["4"] * len(names), names_line))
    types, types_line = keys.get("TYPE", (["F"] * len(names), names_line))
    counts, counts_line = keys.get("COUNT", (["1"] * len(names), names_line))
    for key, values, number in (("SIZE", sizes, sizes_line), ("TYPE", types, types_line),
                                ("COUNT", counts, counts_line)):
        if len(values) != len(names):
            raise InputError(f"{key} has {len(values)} values for {len(names)} FIELDS",
                             file=path, line=number)
    fields = []
    for name, size, kind, count in zip(names, sizes, types, counts, strict=True):
        pcd_type = (kind.upper(), int(size)) if size.isdigit() else None
        if pcd_type not in TYPES or not count.isdigit() or int(count) < 1:
            raise InputError(f"field {name}: {kind} of {size} bytes, {count} a point, is not a "
                             f"PCD type (F 4/8, U or I 1/2/4/8)", file=path, line=types_line)
        fields.append(Field(name.lower(), np.dtype("<" + TYPES[pcd_type]), int(count)))
    if not {"x", "y", "z"} <= {f.name for f in fields}:
        raise InputError(f"no x, y and z fields (found: {', '.join(names)})", file=path,
                         line=names_line)
    wide = next((f for f in fields if f.name in ("x", "y", "z") and f.count != 1), None)
    if wide is not None:
        raise InputError(f"field {wide.name} has COUNT {wide.count}: a coordinate is one value "
                         "a point", file=path, line=counts_line)
    return fields


def _points(path: Path, keys: dict[str, tuple[list[str], int]], line: int) -> int:
    """POINTS, else WIDTH x HEIGHT (organised clouds, as a depth camera's, give both)."""
    if "POINTS" in keys:
        values, line = keys["POINTS"]
        if values and values[0].isdigit():
            return int(values[0])
    elif "WIDTH" in keys:
        width, line = keys["WIDTH"]
        height = keys.get("HEIGHT", (["1"], line))[0]
        if width and height and width[0].isdigit() and height[0].isdigit():
            return int(width[0]) * int(height[0])
    raise InputError("the header gives no POINTS (nor WIDTH and HEIGHT)", file=path, line=line)


def _record(header: Header) -> np.dtype:
    """A point as packed binary; fields by position, as names may repeat (padding "_")."""
    return np.dtype([(f"f{i}", f.dtype, (f.count,) if f.count > 1 else ())
                     for i, f in enumerate(header.fields)])


def _binary(path: Path, raw: BinaryIO, header: Header, partial: bool) -> Columns:
    record = _record(header)
    body = raw.read(header.points * record.itemsize)
    whole = len(body) // record.itemsize
    if whole < header.points and not partial:
        raise InputError(f"truncated: {header.points:,} points of {record.itemsize} bytes need "
                         f"{header.points * record.itemsize:,} bytes, the file holds "
                         f"{len(body):,}" + partial_hint(whole), file=path)
    records = np.frombuffer(body, record, count=whole)
    return _named(header, [records[f"f{i}"] for i in range(len(header.fields))])


def _compressed(path: Path, raw: BinaryIO, header: Header) -> Columns:
    """PCL's binary_compressed: two uint32 sizes (compressed, uncompressed), then LZF data
    that unpacks to all of the first field, then all of the second, ..."""
    import lzf  # python-neo-lzf

    n, head = header.points, raw.read(8)
    if n == 0:
        return _named(header, [np.zeros(0, f.dtype) for f in header.fields])
    if len(head) < 8:
        raise InputError("truncated: the file ends before its compressed points start",
                         file=path)
    compressed, size = (int(v) for v in np.frombuffer(head, "<u4"))
    # PCL leaves padding ("_") out of the compressed data; other writers keep it
    fields = header.fields if size == n * sum(f.size for f in header.fields) else \
        [f for f in header.fields if f.name != "_"]
    if size != n * sum(f.size for f in fields):
        raise InputError(f"the compressed points are said to unpack to {size:,} bytes, but "
                         f"{n:,} points of these fields take {n * sum(f.size for f in fields):,}"
                         ": the file is damaged", file=path)
    check_memory(path, 2.0 * size + n * 48.0, f"a cloud of {n:,} points")
    packed = raw.read(compressed)
    if len(packed) < compressed:  # LZF unpacks only whole, and the fields come one by one
        raise InputError(f"truncated: the compressed points need {compressed:,} bytes, the "
                         f"file holds {len(packed):,}; compressed points cannot be read in "
                         "part", file=path)
    try:
        data = lzf.decompress(packed, size) or b""
    except ValueError:
        data = b""
    if len(data) != size:
        raise InputError(f"the compressed points unpack to {len(data):,} bytes, not the "
                         f"{size:,} the file says: the file is damaged", file=path)
    values, offset = [], 0
    for f in fields:
        column = np.frombuffer(data, f.dtype, count=n * f.count, offset=offset)
        values.append(column.reshape(n, f.count) if f.count > 1 else column)
        offset += n * f.size
    return _named(Header(fields, n, header.data, header.line), values)


def _ascii(path: Path, raw: BinaryIO, header: Header, partial: bool) -> Columns:
    start = raw.tell()
    first = next((ln for ln in raw if ln.strip()), b"").decode("ascii", "replace")
    raw.seek(start)
    width = sum(f.count for f in header.fields)
    table = read_rows(path, raw, delimiter=delimiter_of(first), width=width,
                      rows=header.points, skip=header.line).table
    if len(table) < header.points and not partial:
        raise InputError(f"truncated: the header announces {header.points:,} points, the file "
                         f"holds {len(table):,}" + partial_hint(len(table)), file=path)
    values, column = [], 0
    for f in header.fields:
        values.append(table[:, column] if f.count == 1 else table[:, column:column + f.count])
        column += f.count
    return _named(header, values)


def _named(header: Header, values: list[NDArray]) -> Columns:
    """Columns by lower-case field name; the first of a repeated name."""
    columns: Columns = {}
    for f, column in zip(header.fields, values, strict=True):
        columns.setdefault(f.name, column)
    return columns


def _cloud(columns: Columns, header: Header) -> Cloud:
    xyz = np.column_stack([columns[a].astype(np.float64) for a in "xyz"])
    kinds = {f.name: f.dtype.kind for f in header.fields}
    colors = colors_from(columns, kinds)
    packed = columns.get("rgb", columns.get("rgba"))
    if colors is None and packed is not None and packed.ndim == 1:
        bits = _packed(packed)
        colors = np.column_stack([(bits >> 16) & 255, (bits >> 8) & 255, bits & 255]).astype(
            np.uint8)
    # ASPRS classes from "classification"; PCL's "label" is a segment, not a class
    return Cloud(xyz, classes_from(columns), colors)


def _packed(values: NDArray) -> NDArray[np.uint32]:
    """A packed 0xAARRGGBB colour as its 32 bits. PCL stores it in a float field; in ASCII
    files PCL now writes the bits as an integer, older writers wrote the float."""
    if values.dtype == np.float32:
        return values.view(np.uint32)
    if values.dtype.kind in "ui":
        return values.astype(np.uint32)
    finite = np.nan_to_num(values)
    if np.all((finite >= 0) & (finite < 2**32) & (finite == np.round(finite))):
        return finite.astype(np.uint32)
    return finite.astype(np.float32).view(np.uint32)
