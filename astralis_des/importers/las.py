"""LAS, LAZ and COPC: every version (1.0 to 1.4) and point format (0 to 10), streamed.

The file's bytes are checked first (:mod:`.lasfile`, :mod:`.lazfile`), so that what would
make laspy or lazrs loop, abort or ask for the memory of a claimed count is mended or refused
before a point is read. Points are streamed (laspy's ``chunk_iterator``) and kept as the file
stores them, 12 bytes a point plus classes and colours; beyond ``max_points`` every k-th point
is kept. A LAZ is read with lazrs, or laszip (LASzip 1.x's point-wise compressor, or an
error); one cut short reads its whole chunks. A COPC of more points than needed is read down
to the level that fits.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from astralis_des.errors import InputError
from astralis_des.importers.lasfile import VARIABLE, Layout, Mended, counting, layout, problems
from astralis_des.importers.lasunits import las_crs, las_units
from astralis_des.importers.lazfile import POINTWISE, Node, copc_nodes, laz_of, laz_tail
from astralis_des.importers.pointcloud import library_error, partial_hint
from astralis_des.importers.source import Cloud, ReadRequest, max_points, reader

log = logging.getLogger(__name__)

CHUNK = 1_000_000  # points decompressed at a time
PARALLEL_BYTES = 1 << 28  # the biggest decompressed chunk lazrs's parallel reader may hold
_PASSING = (KeyboardInterrupt, SystemExit, GeneratorExit)


@reader("las", "laz", memory_per_byte=0.0)
def read_las(path: Path, request: ReadRequest) -> Cloud:
    """The points of a LAS/LAZ/COPC file, with their classes and colours; units from the
    header's coordinate system."""
    keep = max_points(request)
    with path.open("rb") as raw:
        found = layout(path, raw)
        if found.compressed:
            found = replace(found, laz=laz_of(path, raw, found))
        copc = found.is_copc and found.laz is not None and found.count > keep
        octree = copc_nodes(path, raw, found) if copc else None
    backends = _backends(path, found)
    notes = problems(found)
    count = found.count
    if not found.compressed and count > found.whole_points:
        _short(path, found.whole_points, count, request, "")
        found = counting(found, found.whole_points)  # --partial: what the file holds
    if octree is not None:
        cloud, header = _read_copc(path, found, octree, keep, request)
    else:
        found = _chunks_checked(path, found, request)
        cloud, header = _read_stream(path, found, backends, keep, request)
    if found.count < count:
        notes.append(f"--partial: read the {found.count:,} whole points the file holds, of "
                     f"the {count:,} its header announces")
    cloud.notes[:0] = notes
    with _laspy_quiet():
        cloud.crs_scale, cloud.crs_vertical, cloud.crs_note = las_units(header)
        cloud.crs_wkt = las_crs(header)
    cloud.resolution = float(min(header.scales[:2]))
    return cloud


def _backends(path: Path, found: Layout) -> tuple[Any, ...]:
    """The LAZ backends to try, in order: lazrs, then laszip; laszip alone for LASzip's
    point-wise compressor, which lazrs cannot read; lazrs's sequential reader alone for a
    LAZ whose chunk table is lost, and before laszip for chunks too big for the parallel
    reader, which holds a whole chunk decompressed."""
    import laspy

    if found.laz is None:
        return ()
    available = laspy.LazBackend.detect_available()
    lazrs = [b for b in available if b in (laspy.LazBackend.LazrsParallel,
                                          laspy.LazBackend.Lazrs)][:1]
    laszip = [b for b in available if b == laspy.LazBackend.Laszip]
    if found.laz.compressor == POINTWISE:
        if not laszip:
            raise InputError(f"compressed by LASzip {found.laz.major}'s point-wise compressor, "
                             "which only laspy's laszip backend reads: pip install laszip",
                             file=path)
        return tuple(laszip)
    if not lazrs + laszip:
        raise InputError("a LAZ file needs one of laspy's LAZ backends: pip install lazrs",
                         file=path)
    sequential = [b for b in available if b == laspy.LazBackend.Lazrs]
    if found.laz.chunks is None and found.laz.whole is None and sequential:
        return tuple(sequential)  # an empty table of our own: chunk after chunk
    if found.laz.biggest * found.record_length > PARALLEL_BYTES:
        return tuple(sequential + laszip)
    return tuple(lazrs + laszip)


def _chunks_checked(path: Path, found: Layout, request: ReadRequest) -> Layout:
    """A LAZ's header count against its chunk table: more points than its chunks hold is a
    truncated file (refused, or read as far as its chunks go with --partial); a lost table
    is replaced by an empty one, so that the chunks are read one after another."""
    laz = found.laz
    if laz is None or laz.compressor == POINTWISE or not found.count:
        return found
    if laz.chunks is None and laz.whole is None and laz.chunk_size == VARIABLE:
        # lazrs would panic without a table to say where each chunk ends
        raise InputError("truncated or damaged: its chunk table cannot be read, and its "
                         "chunks vary in size, so none can be told apart", file=path)
    capacity = laz.capacity
    if laz.whole is not None and capacity is not None:  # layered: chunk by chunk, known
        if found.count > capacity:
            chunks = len(laz.chunks or ())
            _short(path, capacity, found.count, request, f"chunk {len(laz.whole) + 1:,} of "
                   f"{chunks:,} cannot be read" if len(laz.whole) < chunks else "")
            found = counting(found, capacity)
        return found if laz.chunks is not None else laz_tail(found)
    if capacity is None:
        return laz_tail(found)
    if found.count <= capacity:
        return found
    if laz.chunk_size == VARIABLE:
        _short(path, capacity, found.count, request, "")
        return counting(found, capacity)
    whole = capacity - laz.chunk_size  # the last chunk may hold fewer: no count says
    if not (request.partial and whole):
        chunks = len(laz.chunks or ())
        raise InputError(f"truncated: the header announces {found.count:,} points, more than "
                         f"the {chunks:,} chunk{'s' if chunks > 1 else ''} of "
                         f"{laz.chunk_size:,} its chunk table lists can hold"
                         + (f"; pass --partial to import the {whole:,} of its chunks before "
                            "the last" if whole else ""), file=path)
    return counting(found, whole)


class _Points:
    """Chunks of points kept as the file stores them (int32 with the header's scale and
    offset): every ``stride``-th point when there are more than memory allows."""

    def __init__(self, room: int, stride: int, colors: bool, classes: bool) -> None:
        self.stride = stride
        room = max(room, 0)
        self.xyz = np.empty((room, 3), dtype=np.int32)
        self.classes = np.empty(room, dtype=np.uint8) if classes else None
        self.rgb = np.empty((room, 3), dtype=np.uint16) if colors else None
        self.kept = 0
        self.read = 0
        self.header: Any = None  # laspy's, for the scale and offset

    def add(self, chunk: Any) -> None:
        first = (-self.read) % self.stride
        pick = slice(first, None, self.stride)
        self.read += len(chunk)
        n = len(range(first, len(chunk), self.stride))
        if not n:
            return
        if self.kept + n > len(self.xyz):  # a header that undercounts its points
            self._grow(self.kept + n)
        at = slice(self.kept, self.kept + n)
        for axis, name in enumerate("XYZ"):
            self.xyz[at, axis] = np.asarray(chunk[name])[pick]
        if self.classes is not None:
            self.classes[at] = np.asarray(chunk.classification)[pick]
        if self.rgb is not None:
            for axis, name in enumerate(("red", "green", "blue")):
                self.rgb[at, axis] = np.asarray(chunk[name])[pick]
        self.kept += n

    def cut(self, read: int) -> None:
        """Keep the points of the first ``read`` only."""
        self.read = min(self.read, read)
        self.kept = min(self.kept, -(-self.read // self.stride))

    def _grow(self, need: int) -> None:
        size = max(need, 2 * len(self.xyz))
        self.xyz = np.resize(self.xyz, (size, 3))
        if self.classes is not None:
            self.classes = np.resize(self.classes, size)
        if self.rgb is not None:
            self.rgb = np.resize(self.rgb, (size, 3))

    def cloud(self) -> Cloud:
        n = self.kept
        rgb = None
        if self.rgb is not None:
            values = self.rgb[:n]
            rgb = (values >> 8 if values.max(initial=0) > 255 else values).astype(np.uint8)
        return Cloud(self.xyz[:n], None if self.classes is None else self.classes[:n], rgb,
                     step=np.asarray(self.header.scales, dtype=np.float64),
                     ref=np.asarray(self.header.offsets, dtype=np.float64))


def _read_stream(path: Path, found: Layout, backends: tuple[Any, ...], keep: int,
                 request: ReadRequest) -> tuple[Cloud, Any]:
    """Every point in file order (every k-th beyond ``keep``), with the first backend that
    reads the file; a failure after points were read is the file's, not the backend's. A
    LAZ whose chunk table is lost may hold far fewer points than its header says: room for
    them is made as they come."""
    import laspy

    stride = max(math.ceil(found.count / keep), 1) if found.count else 1
    names = set(laspy.PointFormat(found.point_format).dimension_names)
    batch, whole = _batches(found)
    trusted = found.laz is None or found.laz.capacity is not None
    room = math.ceil((found.count if trusted else min(found.count, CHUNK)) / stride)
    failure: BaseException | None = None
    for backend in backends or (None,):
        points = _Points(room, stride, {"red", "green", "blue"} <= names,
                         "classification" in names)
        try:
            _stream(path, found, backend, points, batch, request)
        except _PASSING:
            raise
        except BaseException as exc:  # lazrs raises a PanicException (a BaseException)
            failure = exc
            points.cut(points.read - points.read % whole)
            if points.read:  # the file's data, not the backend: another would fail too
                break
            log.info("%s: the LAZ backend %s failed (%s)", path, backend, exc)
        else:
            failure = None
            break
    if failure is not None and not (request.partial and points.kept):
        if points.read:
            _short(path, points.read, found.count, request, _reason(path, failure))
        raise library_error(path, "LAZ" if found.compressed else "LAS",
                            _exception(failure)) from None
    if points.read < found.count:
        _short(path, points.read, found.count, request, "")
    cloud = points.cloud()
    if failure is not None or points.read < found.count:
        cloud.notes.append(f"--partial: read the {points.read:,} points before the file "
                           f"ends, of the {found.count:,} its header announces")
    if points.kept < found.count:
        cloud.held = points.read
    if stride > 1:
        cloud.notes.append(f"kept every {_nth(stride)} point ({points.kept:,} of "
                           f"{points.read:,}) to stay within --max-points {keep:,}")
    return cloud, points.header


def _batches(found: Layout) -> tuple[int, int]:
    """Points to read at a time, and the run of points a failure loses: whole chunks of a
    chunked LAZ (one at a time when its table is lost, to keep every whole one)."""
    laz = found.laz
    if laz is None or laz.compressor == POINTWISE or laz.chunk_size == VARIABLE:
        return CHUNK, 1
    size = laz.chunk_size
    if laz.chunks is None or size > CHUNK:
        return min(size, CHUNK), size
    return size * (CHUNK // size), size


def _stream(path: Path, found: Layout, backend: Any, points: _Points, batch: int,
            request: ReadRequest) -> None:
    import laspy

    with _laspy_quiet(), path.open("rb") as raw, laspy.open(
            Mended(raw, found.patches), laz_backend=backend or ()) as opened:
        points.header = opened.header
        for chunk in opened.chunk_iterator(batch):
            points.add(chunk)
            if request.progress is not None:
                request.progress(points.read, found.count)


def _exception(exc: BaseException) -> Exception:
    """lazrs's panics are BaseExceptions; the message is what matters."""
    return exc if isinstance(exc, Exception) else RuntimeError(str(exc))


def _nth(k: int) -> str:
    return f"{k}{'th' if 10 <= k % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(k % 10, 'th')}"


def _reason(path: Path, exc: BaseException) -> str:
    """The library's complaint, shortened: "truncated ..." when the data ended early."""
    message = library_error(path, "LAS", _exception(exc)).message
    return message if message.startswith("truncated") else " ".join(str(exc).split())[:120]


def _short(path: Path, held: int, count: int, request: ReadRequest, why: str) -> None:
    """A file that ends, or breaks, before its header's count of points: refused, unless
    ``partial`` (then read as far as it goes)."""
    if request.partial and held:
        return
    if not why or why.startswith("truncated"):
        raise InputError(f"truncated: the header announces {count:,} points, the file holds "
                         f"{held:,}{partial_hint(held)}", file=path)
    raise InputError(f"damaged after {held:,} of its {count:,} points ({why})"
                     f"{partial_hint(held)}", file=path)


@contextmanager
def _laspy_quiet() -> Iterator[None]:
    """laspy logs a backend that fails, a short read and a VLR it cannot parse as errors and
    warnings; what matters is said here in one line of our own, so its records are kept from
    the console."""
    logger = logging.getLogger("laspy")
    before = logger.propagate, logger.level
    logger.propagate, logger.level = False, logging.CRITICAL + 1
    try:
        yield
    finally:
        logger.propagate, logger.level = before


def _read_copc(path: Path, found: Layout, octree: tuple[float, list[Node]], keep: int,
               request: ReadRequest) -> tuple[Cloud, Any]:
    """The coarse levels of a COPC octree, down to the deepest whose points (with all above
    it) number at most ``keep`` (the root level thinned when even it is more), one level at
    a time by laspy's ``CopcReader``: the cloud thinned evenly in space, the rest never
    read."""
    import laspy

    spacing, nodes = octree
    per_level: dict[int, int] = {}
    for node in nodes:
        per_level[node.level] = per_level.get(node.level, 0) + node.points
    levels, total = 0, 0
    for level in sorted(per_level):
        if total + per_level[level] > keep and levels:
            break
        total, levels = total + per_level[level], level + 1
    stride = max(math.ceil(total / keep), 1)
    try:
        with _laspy_quiet(), path.open("rb") as raw, laspy.CopcReader(
                Mended(raw, found.patches)) as copc:
            copc.header.read_evlrs(copc.source)  # the CRS may be in one; CopcReader skips them
            names = set(copc.header.point_format.dimension_names)
            points = _Points(math.ceil(total / stride), stride, {"red", "green", "blue"} <= names,
                             "classification" in names)
            points.header = copc.header
            for level in range(levels):
                points.add(copc.query(level=level))
                if request.progress is not None:
                    request.progress(points.read, total)
    except _PASSING:
        raise
    except BaseException as exc:  # lazrs's panics are BaseExceptions
        raise library_error(path, "COPC", _exception(exc)) from None
    cloud = points.cloud()
    cloud.held = found.count
    thinned = f", every {_nth(stride)} point of them" if stride > 1 else ""
    cloud.notes.append(f"COPC: read octree levels 0 to {levels - 1} of {max(per_level) + 1} "
                       f"({len(cloud):,} of {found.count:,} points{thinned}, spaced about "
                       f"{spacing / 2 ** (levels - 1):.3g} file units): within --max-points "
                       f"{keep:,}")
    return cloud, points.header
