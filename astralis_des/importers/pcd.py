"""PCD (the Point Cloud Library's format), ASCII and binary.

None of the project's libraries reads PCD, so this is a small reader on numpy: the text header
says the fields, their sizes, types and counts; the points follow as text rows or as packed
records. ``binary_compressed`` (LZF) is refused with a way out.
"""

from __future__ import annotations

from pathlib import Path
from typing import BinaryIO

import numpy as np

from astralis_des.errors import InputError
from astralis_des.importers.source import Cloud, ReadRequest, reader

HEADER_KEYS = ("VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT",
               "POINTS", "DATA")
TYPES = {("F", 4): "<f4", ("F", 8): "<f8", ("U", 1): "u1", ("U", 2): "<u2", ("U", 4): "<u4",
         ("U", 8): "<u8", ("I", 1): "i1", ("I", 2): "<i2", ("I", 4): "<i4", ("I", 8): "<i8"}
MAX_HEADER_LINES = 64


@reader("pcd", memory_per_byte=6.0)
def read_pcd(path: Path, request: ReadRequest) -> Cloud:
    with path.open("rb") as raw:
        header, line = _header(path, raw)
        data_kind = header["DATA"][0].lower()
        dtype = _record(path, header)
        count = _count(path, header)
        if data_kind == "binary":
            body = raw.read()
            if len(body) < count * dtype.itemsize:
                raise InputError(f"truncated: {count:,} points of {dtype.itemsize} bytes need "
                                 f"{count * dtype.itemsize:,} bytes, the file holds {len(body):,}",
                                 file=path)
            records = np.frombuffer(body, dtype=dtype, count=count)
            return _cloud(records, dtype)
        if data_kind == "ascii":
            return _ascii(path, raw, dtype, count, line)
    if data_kind == "binary_compressed":
        raise InputError("binary_compressed PCD is not supported; convert it first, e.g. "
                         "`pcl_convert_pcd_ascii_binary FILE OUT.pcd 1`", file=path, line=line)
    raise InputError(f"DATA '{data_kind}' is not ascii, binary or binary_compressed",
                     file=path, line=line)


def _header(path: Path, raw: BinaryIO) -> tuple[dict[str, list[str]], int]:
    header: dict[str, list[str]] = {}
    for number in range(1, MAX_HEADER_LINES + 1):
        line = raw.readline()
        if not line:
            break
        text = line.decode("ascii", "replace").strip()
        if not text or text.startswith("#"):
            continue
        key, *values = text.split()
        if key.upper() not in HEADER_KEYS:
            shown = repr(key[:20] + ("..." if len(key) > 20 else ""))
            raise InputError(f"{shown} is not a PCD header key: not a PCD file", file=path,
                             line=number)
        header[key.upper()] = values
        if key.upper() == "DATA":
            missing = [k for k in ("FIELDS", "SIZE", "TYPE") if k not in header]
            if missing:
                raise InputError(f"the header has no {', '.join(missing)}", file=path,
                                 line=number)
            return header, number
    raise InputError("no PCD header (no DATA line)", file=path)


def _record(path: Path, header: dict[str, list[str]]) -> np.dtype:
    fields, sizes, types = header["FIELDS"], header["SIZE"], header["TYPE"]
    counts = header.get("COUNT", ["1"] * len(fields))
    if not len(fields) == len(sizes) == len(types) == len(counts):
        raise InputError("FIELDS, SIZE, TYPE and COUNT have different lengths", file=path)
    parts: list[tuple[str, str, tuple[int, ...]]] = []
    for name, size, kind, count in zip(fields, sizes, types, counts, strict=True):
        key = (kind.upper(), int(size)) if size.isdigit() else None
        if key not in TYPES or not count.isdigit():
            raise InputError(f"field {name}: type {kind}{size} x {count} is not a PCD type",
                             file=path)
        shape = () if int(count) == 1 else (int(count),)
        parts.append((name if name != "_" else f"_pad{len(parts)}", TYPES[key], shape))
    names = {p[0] for p in parts}
    if not {"x", "y", "z"} <= names:
        raise InputError(f"no x, y and z fields (found: {', '.join(fields)})", file=path)
    return np.dtype(parts)


def _count(path: Path, header: dict[str, list[str]]) -> int:
    for key in ("POINTS", "WIDTH"):
        if key in header and header[key] and header[key][0].isdigit():
            count = int(header[key][0])
            if key == "WIDTH" and header.get("HEIGHT", ["1"])[0].isdigit():
                count *= int(header["HEIGHT"][0])
            return count
    raise InputError("the header gives no POINTS", file=path)


def _ascii(path: Path, raw: BinaryIO, dtype: np.dtype, count: int, line: int) -> Cloud:
    width = sum(int(np.prod(dtype[n].shape)) or 1 for n in dtype.names or ())
    try:
        table = np.loadtxt(raw, dtype=np.float64, ndmin=2)
    except ValueError as exc:
        raise InputError(f"points: {' '.join(str(exc).split())}", file=path) from None
    if table.shape[1] != width and len(table):
        raise InputError(f"{table.shape[1]} values a row where the fields need {width}",
                         file=path, line=line + 1)
    if len(table) < count:
        raise InputError(f"truncated: the header announces {count:,} points, the file holds "
                         f"{len(table):,}", file=path)
    records = np.zeros(len(table), dtype=dtype)
    column = 0
    for name in dtype.names or ():
        n = int(np.prod(dtype[name].shape)) or 1
        values = table[:, column:column + n]
        records[name] = values[:, 0] if n == 1 else values
        column += n
    return _cloud(records, dtype)


def _cloud(records: np.ndarray, dtype: np.dtype) -> Cloud:
    xyz = np.column_stack([records[a].astype(float) for a in "xyz"])
    colors = None
    names = dtype.names or ()
    if "rgb" in names or "rgba" in names:
        packed = records["rgb" if "rgb" in names else "rgba"]
        bits = packed.astype(np.float32).view(np.uint32) if packed.dtype.kind == "f" else \
            packed.astype(np.uint32)
        colors = np.column_stack([(bits >> 16) & 255, (bits >> 8) & 255, bits & 255]).astype(
            np.uint8)
    classification = None
    if "classification" in names:  # ASPRS classes; PCL's "label" is a segment, not a class
        classification = records["classification"].astype(np.uint8)
    return Cloud(xyz, classification, colors)
