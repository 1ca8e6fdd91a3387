"""What a LAZ file's own bytes say before lazrs or laszip decompress it: its LASzip VLR checked
against the header, its chunk table, the layers of its LAS 1.4 chunks, and a COPC octree.

LAZ backends trust these bytes with memory and time: a chunk table that claims four billion
chunks (lazrs asks for the memory at once and the process aborts), chunks of 268 million
points (lazrs's parallel reader zeroes gigabytes for one), a LAS 1.4 chunk whose layers say
gigabytes (lazrs reads each layer whole), a COPC page that points at itself (laspy walks it
for ever). Each is found here from a few bytes a chunk; a table that is lost (a LAZ cut short)
is replaced by an empty one (:func:`laz_tail`), so that the chunks read one after another.
"""

from __future__ import annotations

import io
import struct
from dataclasses import dataclass, replace
from pathlib import Path
from typing import BinaryIO

from astralis_des.errors import InputError
from astralis_des.importers.lasfile import COPC_INFO, LASZIP, VARIABLE, VLR_HEADER, Layout, Laz

POINTWISE = 1  # LASzip's compressor of version 1.x: no chunks
CHUNKED = (2, 3)  # LASzip's point-wise and layered chunked compressors
LAYERED = 3  # LAS 1.4's point formats: each chunk a raw point, its count, its layers' sizes
LASZIP_FIXED = struct.Struct("<HHBBHIIqqH")  # the LASzip VLR before its items (34 bytes)
# Layers of each LAS 1.4 LASzip item: Point14, RGB14, RGBNIR14, Wavepacket14 (Byte14: one a
# byte).
LAYERS = {10: 9, 11: 1, 12: 2, 13: 1}
BYTE14 = 14
ENTRY = struct.Struct("<iiiiQii")  # a COPC hierarchy entry: key, offset, bytes, points


def laz_of(path: Path, raw: BinaryIO, found: Layout) -> Laz:
    """The LASzip VLR of a compressed file, checked against its header, its chunk table when
    the table is sound, and its sound layered chunks."""
    where = found.vlr(*LASZIP)
    if where is None:
        raise InputError("not a readable LAZ file (its points are compressed, but it has no "
                         "LASzip VLR to say how)", file=path)
    raw.seek(where - VLR_HEADER + 20)
    length = struct.unpack("<H", raw.read(2))[0]
    raw.seek(where)
    record = raw.read(length)
    count = struct.unpack_from("<H", record, 32)[0] if len(record) >= LASZIP_FIXED.size else -1
    if count < 1 or len(record) < LASZIP_FIXED.size + 6 * count:
        raise InputError(f"not a readable LAZ file (its LASzip VLR of {len(record)} bytes is "
                         "too short for what it describes)", file=path)
    compressor, _coder, major, _, _, _, chunk_size, *_ = LASZIP_FIXED.unpack_from(record)
    items = [struct.unpack_from("<HHH", record, 34 + 6 * i)[:2] for i in range(count)]
    if compressor not in (POINTWISE, *CHUNKED) or (chunk_size == 0 and compressor != POINTWISE):
        raise InputError(f"not a readable LAZ file (its LASzip VLR names compressor "
                         f"{compressor} with chunks of {chunk_size:,} points)", file=path)
    if sum(size for _, size in items) != found.record_length:
        raise InputError(f"not a readable LAZ file (its LASzip VLR describes points of "
                         f"{sum(size for _, size in items)} bytes, its header "
                         f"{found.record_length})", file=path)
    chunks = _chunk_table(raw, found, record) if compressor in CHUNKED else None
    known = compressor == LAYERED and all(k in LAYERS or k == BYTE14 for k, _ in items)
    layers = sum(n if k == BYTE14 else LAYERS.get(k, 0) for k, n in items) if known else 0
    laz = Laz(compressor, major, chunk_size, bytes(record), chunks, layers)
    return replace(laz, whole=_whole_chunks(raw, found, laz)) if laz.layers else laz


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


def _whole_chunks(raw: BinaryIO, found: Layout, laz: Laz) -> tuple[tuple[int, int], ...]:
    """(points, bytes) of each layered chunk from the first, up to the first that is not
    sound (its layers overrun its bytes, or the file), or until the header's count is
    reached. Without a chunk table, each chunk's end is found from its layers' sizes."""
    whole: list[tuple[int, int]] = []
    at, total, table = found.offset + 8, 0, laz.chunks
    fixed = laz.chunk_size != VARIABLE
    while total < found.count and (table is None or len(whole) < len(table)):
        end = at + table[len(whole)][1] if table else found.size
        span = _layered_chunk(raw, at, min(end, found.size), found.record_length, laz.layers)
        if span is None or (fixed and span[0] > laz.chunk_size) or (
                table and not fixed and span[0] != table[len(whole)][0]):
            break
        whole.append((span[0], end - at if table else span[1]))
        total += span[0]
        at += whole[-1][1]
        if fixed and span[0] < laz.chunk_size:  # a chunk short of its size is the last
            break
    return tuple(whole)


def _layered_chunk(raw: BinaryIO, at: int, end: int, record_length: int, layers: int
                   ) -> tuple[int, int] | None:
    """(points, bytes) of the layered chunk at ``at`` (a raw point, the count, the layers'
    sizes, the layers), when it ends by ``end``."""
    head = record_length + 4 + 4 * layers
    if at + head > end:
        return None
    raw.seek(at + record_length)
    points, *sizes = struct.unpack(f"<{1 + layers}I", raw.read(4 + 4 * layers))
    size = head + sum(sizes)
    return (points, size) if points > 0 and at + size <= end else None


def laz_tail(found: Layout) -> Layout:
    """``found`` with a chunk table of its own one byte past the end of the file, for a LAZ
    whose table is lost (cut short): the table of its whole layered chunks, or an empty one,
    so that lazrs reads chunk after chunk as far as they go."""
    table = struct.pack("<II", 0, 0)
    if found.laz is not None and found.laz.whole:
        import lazrs

        written = io.BytesIO()
        lazrs.write_chunk_table(written, list(found.laz.whole), lazrs.LazVlr(found.laz.record))
        table = written.getvalue()
    tail = found.size + 1
    patches = dict(found.patches)
    patches[found.offset] = struct.pack("<q", tail)
    patches[tail] = table
    return replace(found, patches=patches)


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
    root page as laspy's ``CopcReader`` walks it (a node's children are looked for under it
    only), each page read once. A page read twice (laspy would loop for ever), a node outside
    the file or whose chunk's layers overrun it, or nodes of more points or bytes than the
    file has (laspy would ask for the memory) is an :class:`InputError`."""
    where = found.vlr(*COPC_INFO)
    raw.seek(where or 0)
    info = raw.read(160)
    if where is None or len(info) < 160:
        raise InputError("not a readable COPC file (its COPC info VLR is too short)", file=path)
    spacing, root_at, root_size = struct.unpack_from("<dQQ", info, 32)
    entries: dict[tuple[int, ...], tuple[int, int, int]] = {}
    pages: set[int] = set()

    def page(at: int, size: int) -> None:
        if at in pages:
            raise InputError(f"not a readable COPC file (its octree loops: the hierarchy page "
                             f"at byte {at:,} is reached twice)", file=path)
        if size < 0 or at + size > found.size or size % ENTRY.size:
            raise InputError(f"not a readable COPC file (a hierarchy page of {size:,} bytes at "
                             f"byte {at:,}, in a file of {found.size:,})", file=path)
        pages.add(at)
        raw.seek(at)
        for d, x, y, z, offset, nbytes, points in ENTRY.iter_unpack(raw.read(size)):
            entries[(d, x, y, z)] = (offset, nbytes, points)

    page(root_at, root_size)
    nodes: list[Node] = []
    held = spans = 0  # points and bytes of the nodes so far
    layers = found.laz.layers if found.laz is not None else 0
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
        held, spans = held + max(points, 0), spans + max(nbytes, 0)
        start = found.offset + 1 if points else 0  # a node of no points has no chunk
        inside = start <= offset and nbytes >= bool(points) and offset + nbytes <= found.size
        if inside and points and layers:
            span = _layered_chunk(raw, offset, offset + nbytes, found.record_length, layers)
            inside = span is not None and span[0] == points
        if points < 0 or not inside or held > found.count or spans > found.size:
            raise InputError(f"not a readable COPC file (octree node {key} holds {points:,} "
                             f"points in {nbytes:,} bytes at byte {offset:,}; the file has "
                             f"{found.size:,} bytes and {found.count:,} points)", file=path)
        if points:
            nodes.append(Node(key[0], offset, nbytes, points))
        d, x, y, z = key
        todo.extend((d + 1, 2 * x + i, 2 * y + j, 2 * z + k)
                    for i in (0, 1) for j in (0, 1) for k in (0, 1))
    if not nodes:
        raise InputError(f"not a readable COPC file (its octree holds no points, its header "
                         f"announces {found.count:,})", file=path)
    return spacing, nodes
