"""What a LAS/LAZ file's own bytes say before laspy reads it: its header checked against the
file's size, its VLRs and EVLRs walked, its LASzip VLR and chunk table checked, and a file
object that mends a header laspy would choke on.

Real files break the specification in ways laspy and its LAZ backends do not survive: a VLR
count of a billion (laspy reads VLRs until memory runs out), more VLRs than fit before the
points, EVLRs past the end of the file, a chunk table that claims four billion chunks (lazrs
asks for the memory at once and the process aborts), or none at all (a LAZ cut short).
:func:`layout` finds these from the header, the VLR headers and the chunk table alone, and
:class:`Mended` hands laspy a header with the counts that fit and, for a LAZ whose chunk
table is lost, an empty table of its own.
"""

from __future__ import annotations

import io
import struct
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import BinaryIO

from astralis_des.errors import InputError

SIGNATURE = b"LASF"
HEADER_MIN = 227  # bytes of a LAS 1.0 header
VLR_HEADER = 54
EVLR_HEADER = 60
# Bytes of each point format's standard fields (LAS 1.4, R15, table 7 onwards).
POINT_SIZES = {0: 20, 1: 28, 2: 26, 3: 34, 4: 57, 5: 63, 6: 30, 7: 36, 8: 38, 9: 59, 10: 67}
VLR_COUNT_AT, FORMAT_AT, LEGACY_COUNT_AT = 100, 104, 107
EVLR_START_AT, EVLR_COUNT_AT, COUNT_AT = 235, 243, 247
LASZIP = (b"laszip encoded", 22204)
COPC_INFO = (b"copc", 1)
POINTWISE = 1  # LASzip's compressor of version 1.x: no chunks
CHUNKED = (2, 3)  # LASzip's point-wise and layered chunked compressors
VARIABLE = 0xFFFFFFFF  # a chunk size that says each chunk's count is in the chunk table
LASZIP_FIXED = struct.Struct("<HHBBHIIqqH")  # the LASzip VLR before its items (34 bytes)
ENTRY = struct.Struct("<iiiiQii")  # a COPC hierarchy entry: key, offset, bytes, points


@dataclass(frozen=True)
class Laz:
    """A LAZ file's LASzip VLR and chunk table, as far as they are sound."""

    compressor: int  # 1: point-wise; 2, 3: chunked
    major: int  # LASzip's version that wrote it
    chunk_size: int  # points a chunk; VARIABLE: as the chunk table says
    record: bytes  # the LASzip VLR's data, for lazrs
    chunks: tuple[tuple[int, int], ...] | None  # (points, bytes) a chunk, when the table reads

    @property
    def capacity(self) -> int | None:
        """The most points the chunk table allows (each fixed-size chunk full)."""
        if self.chunks is None:
            return None
        if self.chunk_size == VARIABLE:
            return sum(points for points, _ in self.chunks)
        return len(self.chunks) * self.chunk_size

    @property
    def biggest(self) -> int:
        """Points in the biggest chunk (as many as a fixed-size chunk may hold)."""
        if self.chunk_size != VARIABLE or not self.chunks:
            return self.chunk_size
        return max(points for points, _ in self.chunks)


@dataclass(frozen=True)
class Layout:
    """A LAS file's header facts, checked against the file."""

    version: tuple[int, int]
    header_size: int
    offset: int  # to the point records
    point_format: int
    record_length: int
    count: int  # points the header announces
    compressed: bool
    size: int  # bytes in the file
    vlrs: tuple[tuple[bytes, int, int], ...]  # (user id, record id, where its data starts)
    vlrs_claimed: int
    evlr_start: int
    evlrs_claimed: int
    evlrs_fit: bool  # the EVLRs start after the points and before the end of the file
    patches: dict[int, bytes] = field(default_factory=dict)  # header bytes laspy should see
    evlrs_whole: int = 0  # EVLRs that fit in the file, one after another
    laz: Laz | None = None  # a compressed file's LASzip VLR and chunk table

    @property
    def whole_points(self) -> int:
        """Uncompressed point records the file holds in full (before its EVLRs)."""
        end = self.evlr_start if self.evlrs_claimed and self.evlrs_fit else self.size
        return max(end - self.offset, 0) // max(self.record_length, 1)

    def vlr(self, user: bytes, record: int) -> int | None:
        """Where the data of the first VLR ``(user, record)`` starts, if there is one."""
        return next((at for u, r, at in self.vlrs if u == user and r == record), None)

    @property
    def is_copc(self) -> bool:
        return bool(self.vlrs) and self.vlrs[0][:2] == COPC_INFO


def layout(path: Path, raw: BinaryIO) -> Layout:
    """The header of ``raw`` (a LAS or LAZ file) and its VLRs, or an :class:`InputError`
    that names what is broken."""
    size = raw.seek(0, io.SEEK_END)
    raw.seek(0)
    head = raw.read(375)
    if len(head) < 4 or head[:4] != SIGNATURE:
        raise InputError(f"not a readable LAS file (it starts with {head[:4]!r}, not "
                         f"{SIGNATURE!r})", file=path)
    if len(head) < HEADER_MIN:
        raise InputError(f"truncated: {size:,} bytes, fewer than a LAS header's {HEADER_MIN}",
                         file=path)
    version = (head[24], head[25])
    header_size, offset, vlr_count = struct.unpack_from("<HII", head, 94)
    format_byte, record_length = head[FORMAT_AT], struct.unpack_from("<H", head, 105)[0]
    count = struct.unpack_from("<I", head, LEGACY_COUNT_AT)[0]
    evlr_start, evlr_count = 0, 0
    if version >= (1, 4) and header_size >= 375 and len(head) >= 375:
        evlr_start, evlr_count = struct.unpack_from("<QI", head, EVLR_START_AT)
        count = struct.unpack_from("<Q", head, COUNT_AT)[0] or count
    point_format = format_byte & 0x3F
    if point_format not in POINT_SIZES:
        raise InputError(f"not a readable LAS file (point format {point_format}; LAS has 0 to "
                         "10)", file=path)
    if record_length < POINT_SIZES[point_format]:
        raise InputError(f"not a readable LAS file (point records of {record_length} bytes, "
                         f"fewer than format {point_format}'s {POINT_SIZES[point_format]})",
                         file=path)
    if not HEADER_MIN <= header_size <= offset <= size:
        raise InputError(f"not a readable LAS file (header of {header_size} bytes, points "
                         f"from byte {offset:,}, in a file of {size:,})", file=path)
    vlrs = _walk_vlrs(raw, header_size, offset, vlr_count)
    patches: dict[int, bytes] = {}
    if len(vlrs) != vlr_count:
        patches[VLR_COUNT_AT] = struct.pack("<I", len(vlrs))
    compressed = bool(format_byte & 0xC0)  # as LASzip reads it: bit 6 marks old LASzip files
    if compressed and format_byte & 0x40:  # laspy knows bit 7 only
        patches[FORMAT_AT] = bytes([point_format | 0x80])
    evlrs_fit = offset <= evlr_start and evlr_start + EVLR_HEADER <= size
    whole = _walk_evlrs(raw, evlr_start, size, evlr_count) if evlrs_fit else 0
    if evlr_count and whole != evlr_count:
        patches[EVLR_COUNT_AT] = struct.pack("<I", whole)
    found = Layout(version, header_size, offset, point_format, record_length, count,
                   compressed, size, tuple(vlrs), vlr_count, evlr_start, evlr_count,
                   evlrs_fit, patches, whole)
    return replace(found, laz=_laz(path, raw, found)) if compressed else found


def _walk_vlrs(raw: BinaryIO, start: int, end: int, claimed: int
               ) -> list[tuple[bytes, int, int]]:
    """The VLRs that fit between the header and the points: at most ``claimed``, each header
    read alone, so a claimed count of a billion costs what the file holds."""
    found: list[tuple[bytes, int, int]] = []
    at = start
    while len(found) < claimed and at + VLR_HEADER <= end:
        raw.seek(at)
        head = raw.read(VLR_HEADER)
        user = head[2:18].split(b"\0", 1)[0]
        record, length = struct.unpack_from("<HH", head, 18)
        if at + VLR_HEADER + length > end:
            break
        found.append((user, record, at + VLR_HEADER))
        at += VLR_HEADER + length
    return found


def _walk_evlrs(raw: BinaryIO, start: int, end: int, claimed: int) -> int:
    """How many of the ``claimed`` EVLRs from ``start`` fit, whole, before ``end``: laspy
    reads each one's data at once, so a length of an exabyte must not reach it."""
    whole, at = 0, start
    while whole < claimed and at + EVLR_HEADER <= end:
        raw.seek(at + 20)
        length = struct.unpack("<Q", raw.read(8))[0]
        if at + EVLR_HEADER + length > end:
            break
        whole += 1
        at += EVLR_HEADER + length
    return whole


def _laz(path: Path, raw: BinaryIO, found: Layout) -> Laz:
    """The LASzip VLR of a compressed file, checked against its header, and its chunk table
    when the table is sound."""
    where = found.vlr(*LASZIP)
    if where is None:
        raise InputError("not a readable LAZ file (its points are compressed, but it has no "
                         "LASzip VLR to say how)", file=path)
    raw.seek(where - VLR_HEADER + 20)
    length = struct.unpack("<H", raw.read(2))[0]
    raw.seek(where)
    record = raw.read(length)
    items = struct.unpack_from("<H", record, 32)[0] if len(record) >= LASZIP_FIXED.size else -1
    if items < 1 or len(record) < LASZIP_FIXED.size + 6 * items:
        raise InputError(f"not a readable LAZ file (its LASzip VLR of {len(record)} bytes is "
                         "too short for what it describes)", file=path)
    compressor, _coder, major, _, _, _, chunk_size, *_ = LASZIP_FIXED.unpack_from(record)
    sizes = sum(struct.unpack_from("<HHH", record, 34 + 6 * i)[1] for i in range(items))
    if compressor not in (POINTWISE, *CHUNKED) or (chunk_size == 0 and compressor != POINTWISE):
        raise InputError(f"not a readable LAZ file (its LASzip VLR names compressor "
                         f"{compressor} with chunks of {chunk_size:,} points)", file=path)
    if sizes != found.record_length:
        raise InputError(f"not a readable LAZ file (its LASzip VLR describes points of {sizes} "
                         f"bytes, its header {found.record_length})", file=path)
    chunks = _chunk_table(raw, found, record) if compressor in CHUNKED else None
    return Laz(compressor, major, chunk_size, bytes(record), chunks)


def _chunk_table(raw: BinaryIO, found: Layout, record: bytes
                 ) -> tuple[tuple[int, int], ...] | None:
    """The chunk table as (points, bytes) a chunk, or None when it is lost or unsound: its
    offset outside the file, or more chunks than bytes, or chunks that overrun it."""
    raw.seek(found.offset)
    start = found.offset + 8
    data = raw.read(8)
    at = struct.unpack("<q", data)[0] if len(data) == 8 else -1
    if at < start and found.size >= start + 8:  # the writer could not seek back: at the end
        raw.seek(found.size - 8)
        at = struct.unpack("<q", raw.read(8))[0]
    if not start <= at <= found.size - 8:
        return None
    raw.seek(at)
    _version, number = struct.unpack("<II", raw.read(8))
    if number == 0 or number > at - start:  # each chunk takes a byte at least
        return None
    try:
        import lazrs

        raw.seek(found.offset)
        table = tuple((int(p), int(b)) for p, b in lazrs.read_chunk_table(raw, lazrs.LazVlr(
            record)))
    except ImportError:
        return None
    except BaseException as exc:  # lazrs's panics are BaseExceptions
        if isinstance(exc, (KeyboardInterrupt, SystemExit)):
            raise
        return None
    if any(p <= 0 or b <= 0 for p, b in table) or sum(b for _, b in table) > at - start:
        return None
    return table


def laz_tail(found: Layout) -> Layout:
    """``found`` with an empty chunk table of its own, one byte past the end of the file: a
    LAZ whose table is lost (cut short) then reads chunk after chunk, as far as it goes."""
    tail = found.size + 1
    patches = dict(found.patches)
    patches[found.offset] = struct.pack("<q", tail)
    patches[tail] = struct.pack("<II", 0, 0)
    return replace(found, patches=patches)


def laszip_compressor(raw: BinaryIO, where: int) -> tuple[int, int]:
    """(compressor, LASzip version major) of the LASzip VLR whose data starts at ``where``."""
    raw.seek(where)
    compressor, _coder, major = struct.unpack("<HHB", raw.read(5))
    return compressor, major


def counting(found: Layout, count: int) -> Layout:
    """``found`` with its header's point count mended to ``count`` (the points a truncated
    file holds in full)."""
    patches = dict(found.patches)
    patches[LEGACY_COUNT_AT] = struct.pack("<I", count if count < 2**32 else 0)
    if found.version >= (1, 4) and found.header_size >= 375:
        patches[COUNT_AT] = struct.pack("<Q", count)
    return replace(found, count=count, patches=patches)


def problems(found: Layout) -> list[str]:
    """What :class:`Mended` mends, for the import's notes."""
    said = []
    if VLR_COUNT_AT in found.patches:
        said.append(f"the header counts {found.vlrs_claimed:,} VLRs, {len(found.vlrs)} fit "
                    "before the points: read those")
    if EVLR_COUNT_AT in found.patches and not found.evlrs_fit:
        said.append(f"the header's {found.evlrs_claimed:,} EVLRs start past the end of the "
                    "file: left out")
    elif EVLR_COUNT_AT in found.patches:
        said.append(f"the header counts {found.evlrs_claimed:,} EVLRs, {found.evlrs_whole} "
                    "fit in the file: read those")
    return said


@dataclass(frozen=True)
class Node:
    """A COPC octree node that holds points: its level, where its LAZ chunk is, its bytes and
    its points."""

    level: int
    offset: int
    size: int
    points: int


def copc_nodes(path: Path, raw: BinaryIO, found: Layout) -> tuple[float, list[Node]]:
    """The spacing of a COPC file's root level and the nodes of its octree, walked from the
    root page as laspy walks it (a node's children are looked for under it only), each page
    read once: a page read twice (a loop), or a node outside the file, is an
    :class:`InputError`."""
    where = found.vlr(*COPC_INFO)
    raw.seek(where or 0)
    info = raw.read(160)
    if where is None or len(info) < 160:
        raise InputError("not a readable COPC file (its COPC info VLR is too short)", file=path)
    spacing, root_at, root_size = struct.unpack_from("<dQQ", info, 32)
    entries: dict[tuple[int, ...], tuple[int, int, int]] = {}
    pages: set[int] = set()

    def page(at: int, size: int) -> None:
        if at in pages or size < 0 or at + size > found.size or size % ENTRY.size:
            raise InputError(f"not a readable COPC file (a hierarchy page of {size:,} bytes at "
                             f"byte {at:,} of {found.size:,}, or read twice)", file=path)
        pages.add(at)
        raw.seek(at)
        for d, x, y, z, offset, nbytes, points in ENTRY.iter_unpack(raw.read(size)):
            entries[(d, x, y, z)] = (offset, nbytes, points)

    page(root_at, root_size)
    nodes: list[Node] = []
    held = 0
    todo: list[tuple[int, ...]] = [(0, 0, 0, 0)]
    while todo:
        key = todo.pop()
        offset, nbytes, points = entries.get(key, (0, 0, -2))
        if points == -1:
            page(offset, nbytes)
            todo.append(key)
            continue
        if points == -2:  # not in the hierarchy: no points under it
            continue
        inside = found.offset < offset and nbytes > 0 and offset + nbytes <= found.size
        held += max(points, 0)
        if points < 0 or (points and not inside) or held > found.count:
            raise InputError(f"not a readable COPC file (octree node {key} holds {points:,} "
                             f"points in {nbytes:,} bytes at byte {offset:,}; the file has "
                             f"{found.size:,} bytes and {found.count:,} points)", file=path)
        if points:
            nodes.append(Node(key[0], offset, nbytes, points))
        d, x, y, z = key
        todo.extend((d + 1, 2 * x + i, 2 * y + j, 2 * z + k)
                    for i in (0, 1) for j in (0, 1) for k in (0, 1))
    return spacing, nodes


class Mended(io.RawIOBase):
    """A read-only file whose bytes at ``patches`` read as given: laspy and its LAZ backends
    see a header they can read, the file on disk is untouched. A patch past the end of the
    file is read there, and what lies between reads as the end of the file."""

    def __init__(self, raw: BinaryIO, patches: dict[int, bytes]) -> None:
        super().__init__()
        self.raw = raw
        self.patches = patches

    def readable(self) -> bool:
        return True

    def seekable(self) -> bool:
        return True

    def seek(self, offset: int, whence: int = io.SEEK_SET) -> int:
        return self.raw.seek(offset, whence)

    def tell(self) -> int:
        return self.raw.tell()

    def readinto(self, buffer: memoryview | bytearray) -> int:  # type: ignore[override]
        start = self.raw.tell()
        n = self.raw.readinto(buffer)  # type: ignore[attr-defined]
        view = memoryview(buffer).cast("B")
        if not n:
            return self._beyond(start, view)
        for at, data in self.patches.items():
            lo, hi = max(at, start), min(at + len(data), start + n)
            if lo < hi:
                view[lo - start:hi - start] = data[lo - at:hi - at]
        return int(n)

    def _beyond(self, start: int, view: memoryview) -> int:
        """Bytes of a patch past the end of the file, from ``start``."""
        for at, data in self.patches.items():
            if at <= start < at + len(data):
                part = data[start - at:start - at + len(view)]
                view[:len(part)] = part
                self.raw.seek(start + len(part))
                return len(part)
        return 0

    def close(self) -> None:
        self.raw.close()
        super().close()
