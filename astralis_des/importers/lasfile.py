"""What a LAS/LAZ file's own bytes say before laspy reads it: its header checked against the
file's size, its VLRs and EVLRs walked (a LAZ's LASzip VLR and chunks: :mod:`.lazfile`), and
a file object that mends a header laspy would choke on.

Real files break the specification in ways laspy does not survive: a VLR count of a billion
(laspy reads VLRs until memory runs out), more VLRs than fit before the points, EVLRs past the
end of the file or longer than it (laspy asks for the memory of the length it reads), a LAS
1.4 header with only its legacy point count. :func:`layout` finds these from the header and
the VLR and EVLR headers alone, and :class:`Mended` hands laspy a header with counts that fit.
"""

from __future__ import annotations

import io
import math
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
VARIABLE = 0xFFFFFFFF  # a LASzip chunk size that says each chunk's count is in the chunk table


@dataclass(frozen=True)
class Laz:
    """A LAZ file's LASzip VLR and chunk table, as far as they are sound."""

    compressor: int  # 1: point-wise; 2, 3: chunked
    major: int  # LASzip's version that wrote it
    chunk_size: int  # points a chunk; VARIABLE: as the chunk table says
    record: bytes  # the LASzip VLR's data, for lazrs
    chunks: tuple[tuple[int, int], ...] | None  # (points, bytes) a chunk, when the table reads
    layers: int = 0  # layers a chunk of a LAS 1.4 point format has (0: not layered)
    whole: tuple[tuple[int, int], ...] | None = None  # layered: (points, bytes) of each sound
    # chunk from the first, found from the chunks themselves

    @property
    def capacity(self) -> int | None:
        """The most points the chunks hold (each fixed-size chunk full, when not layered)."""
        if self.whole is not None:
            return sum(points for points, _ in self.whole)
        if self.chunks is None:
            return None
        if self.chunk_size == VARIABLE:
            return sum(points for points, _ in self.chunks)
        return len(self.chunks) * self.chunk_size

    @property
    def biggest(self) -> int:
        """Points in the biggest chunk (as many as a fixed-size chunk may hold)."""
        chunks = self.whole if self.whole is not None else self.chunks
        if self.chunk_size != VARIABLE or not chunks:
            return self.chunk_size
        return max(points for points, _ in chunks)


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
    laz: Laz | None = None  # a compressed file's LASzip VLR and chunks (:mod:`.lazfile`)

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
    that names what is broken (a LAZ's ``laz`` is :func:`.lazfile.laz_of`'s to add)."""
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
    evlr_start, evlr_count, wide = 0, 0, count
    if version[1] >= 4 and header_size >= 375 and len(head) >= 375:  # as laspy reads it
        evlr_start, evlr_count, wide = struct.unpack_from("<QIQ", head, EVLR_START_AT)
        count = wide or count  # some writers fill the legacy count only
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
    scales, offsets = struct.unpack_from("<3d", head, 131), struct.unpack_from("<3d", head, 155)
    reach = [abs(s) * 2.0**31 + abs(o) for s, o in zip(scales, offsets, strict=True)]
    if not all(math.isfinite(r) for r in reach):  # coordinates would overflow, or be NaN
        raise InputError("not a readable LAS file (its scale factors "
                         f"{', '.join(f'{s:g}' for s in scales)} and offsets "
                         f"{', '.join(f'{o:g}' for o in offsets)} give no finite coordinates)",
                         file=path)
    vlrs = _walk_vlrs(raw, header_size, offset, vlr_count)
    patches: dict[int, bytes] = {}
    if wide != count:  # laspy reads the 64-bit count alone
        patches[COUNT_AT] = struct.pack("<Q", count)
    if len(vlrs) != vlr_count:
        patches[VLR_COUNT_AT] = struct.pack("<I", len(vlrs))
    compressed = bool(format_byte & 0xC0)  # as LASzip reads it: bit 6 marks old LASzip files
    if compressed and format_byte & 0x40:  # laspy knows bit 7 only
        patches[FORMAT_AT] = bytes([point_format | 0x80])
    evlrs_fit = offset <= evlr_start and evlr_start + EVLR_HEADER <= size
    whole = _walk_evlrs(raw, evlr_start, size, evlr_count) if evlrs_fit else 0
    if evlr_count and whole != evlr_count:
        patches[EVLR_COUNT_AT] = struct.pack("<I", whole)
    return Layout(version, header_size, offset, point_format, record_length, count,
                  compressed, size, tuple(vlrs), vlr_count, evlr_start, evlr_count, evlrs_fit,
                  patches, whole)


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


def counting(found: Layout, count: int) -> Layout:
    """``found`` with its header's point count mended to ``count`` (the points a truncated
    file holds in full)."""
    patches = dict(found.patches)
    patches[LEGACY_COUNT_AT] = struct.pack("<I", count if count < 2**32 else 0)
    if found.version[1] >= 4 and found.header_size >= 375:
        patches[COUNT_AT] = struct.pack("<Q", count)
    return replace(found, count=count, patches=patches)


def problems(found: Layout) -> list[str]:
    """What :class:`Mended` mends, for the import's notes."""
    said = []
    if COUNT_AT in found.patches:
        said.append(f"the header's 64-bit point count is 0, its legacy count {found.count:,}: "
                    "read those")
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
