"""LAS, LAZ and COPC: every version (1.0 to 1.4) and point format (0 to 10), streamed.

The header is checked against the file first (:mod:`.lasfile`): a truncated file, a broken VLR
count or a point count the file cannot hold is found before laspy reads a point. Points are
streamed in chunks (laspy's ``chunk_iterator``) into float32 offsets from the first point, so a
cloud costs 12 bytes a point, plus its classes and colours; beyond ``max_points`` every k-th
point is kept. A LAZ is read with lazrs, and, where lazrs cannot (LASzip's point-wise
compressor of version 1.x, or an error), with laspy's other backend, laszip. A COPC whose
points are more than needed is read level by level (laspy's ``CopcReader``) down to the
deepest level that fits.
"""

from __future__ import annotations

import logging
import math
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from astralis_des.errors import InputError
from astralis_des.importers.lasfile import (
    LASZIP,
    POINTWISE,
    Layout,
    Mended,
    counting,
    laszip_compressor,
    layout,
    problems,
)
from astralis_des.importers.pointcloud import library_error
from astralis_des.importers.source import (
    FOOT,
    US_SURVEY_FOOT,
    Cloud,
    ReadRequest,
    max_points,
    reader,
)

log = logging.getLogger(__name__)

CHUNK = 1_000_000  # points decompressed at a time
# EPSG codes of linear units in a GeoTIFF key directory (ProjLinearUnitsGeoKey, 3076).
LINEAR_UNITS = {9001: ("m", 1.0), 9002: ("ft", FOOT), 9003: ("US survey ft", US_SURVEY_FOOT)}
PROJ_LINEAR_UNITS, VERTICAL_UNITS = 3076, 4099
_WKT_UNIT = re.compile(r'(?:LENGTH)?UNIT\[\s*"([^"]+)"\s*,\s*([0-9.eE+-]+)')
_ANGULAR = ("degree", "radian", "grad", "arc")
_PASSING = (KeyboardInterrupt, SystemExit, GeneratorExit)


@reader("las", "laz", memory_per_byte=0.0)
def read_las(path: Path, request: ReadRequest) -> Cloud:
    """The points of a LAS/LAZ/COPC file, with their classes and colours; units from the
    header's coordinate system."""
    import laspy

    with path.open("rb") as raw:
        found = layout(path, raw)
        backends = _backends(path, raw, found)
    notes = problems(found)
    count = found.count
    if not found.compressed and count > found.whole_points:
        _short(path, found.whole_points, count, request, "")
        found = counting(found, found.whole_points)  # --partial: what the file holds
    keep = max_points(request)
    if found.is_copc and count > keep:
        cloud = _read_copc(path, found, keep, request)
    else:
        cloud = _read_stream(path, found, backends, keep, request)
    if found.count < count:
        notes.append(f"--partial: read the {found.count:,} whole points the file holds, of "
                     f"the {count:,} its header announces")
    cloud.notes[:0] = notes
    with laspy.open(Mended(path.open("rb"), found.patches), laz_backend=()) as opened:
        cloud.crs_scale, cloud.crs_vertical, cloud.crs_note = _las_units(opened.header)
        cloud.crs_wkt = _las_crs(opened.header)
        cloud.resolution = float(min(opened.header.scales[:2]))
    return cloud


def _backends(path: Path, raw: Any, found: Layout) -> tuple[Any, ...]:
    """The LAZ backends to try, in order: lazrs, then laszip; laszip alone for LASzip's
    point-wise compressor, which lazrs cannot read."""
    import laspy

    if not found.compressed:
        return ()
    where = found.vlr(*LASZIP)
    if where is None:
        raise InputError("not a readable LAZ file (its points are compressed, but it has no "
                         "LASzip VLR to say how)", file=path)
    compressor, major = laszip_compressor(raw, where)
    available = laspy.LazBackend.detect_available()
    lazrs = [b for b in available if b in (laspy.LazBackend.LazrsParallel,
                                          laspy.LazBackend.Lazrs)][:1]
    laszip = [b for b in available if b == laspy.LazBackend.Laszip]
    if compressor == POINTWISE:
        if not laszip:
            raise InputError(f"compressed by LASzip {major}'s point-wise compressor, which "
                             "only laspy's laszip backend reads: pip install laszip", file=path)
        return tuple(laszip)
    if not lazrs + laszip:
        raise InputError("a LAZ file needs one of laspy's LAZ backends: pip install lazrs",
                         file=path)
    return tuple(lazrs + laszip)


class _Points:
    """Chunks of points kept as the file stores them (int32 with the header's scale and
    offset): every ``stride``-th point when there are more than memory allows."""

    def __init__(self, count: int, stride: int, colors: bool, classes: bool) -> None:
        self.stride = stride
        room = max(min(count, math.ceil(count / stride)), 0)
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
                 request: ReadRequest) -> Cloud:
    """Every point in file order (every k-th beyond ``keep``), with the first backend that
    reads the file; a failure after points were read is the file's, not the backend's."""
    stride = max(math.ceil(found.count / keep), 1) if found.count else 1
    names = _dimensions(found)
    failure: BaseException | None = None
    for backend in backends or (None,):
        points = _Points(found.count, stride, {"red", "green", "blue"} <= names,
                         "classification" in names)
        try:
            _stream(path, found, backend, points, request)
        except _PASSING:
            raise
        except BaseException as exc:  # lazrs raises a PanicException (a BaseException)
            failure = exc
            if points.read:  # the file's data, not the backend: another would fail too
                break
            log.info("%s: the LAZ backend %s failed (%s)", path, backend, exc)
        else:
            failure = None
            break
    if failure is not None and not (request.partial and points.kept):
        if points.read:
            _short(path, points.read, found.count, request, _reason(path, failure))
        raise library_error(path, path.suffix.lstrip(".").upper() or "LAS",
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
    return cloud


def _stream(path: Path, found: Layout, backend: Any, points: _Points,
            request: ReadRequest) -> None:
    import laspy

    with _laspy_quiet(), laspy.open(Mended(path.open("rb"), found.patches),
                                    laz_backend=backend or ()) as opened:
        points.header = opened.header
        for chunk in opened.chunk_iterator(CHUNK):
            points.add(chunk)
            if request.progress is not None:
                request.progress(points.read, found.count)


def _exception(exc: BaseException) -> Exception:
    """lazrs's panics are BaseExceptions; the message is what matters."""
    return exc if isinstance(exc, Exception) else RuntimeError(str(exc))


def _nth(k: int) -> str:
    return f"{k}{'th' if 10 <= k % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(k % 10, 'th')}"


def _dimensions(found: Layout) -> set[str]:
    import laspy

    return set(laspy.PointFormat(found.point_format).dimension_names)


def _reason(path: Path, exc: BaseException) -> str:
    """The library's complaint, shortened: "truncated ..." when the data ended early."""
    message = library_error(path, "LAS", _exception(exc)).message
    return message if message.startswith("truncated") else " ".join(str(exc).split())[:120]


def _short(path: Path, held: int, count: int, request: ReadRequest, why: str) -> None:
    """A file that ends, or breaks, before its header's count of points: refused, unless
    ``partial`` (then read as far as it goes)."""
    if request.partial and held:
        return
    hint = f"; pass --partial to import the {held:,} it holds" if held else ""
    if not why or why.startswith("truncated"):
        raise InputError(f"truncated: the header announces {count:,} points, the file holds "
                         f"{held:,}{hint}", file=path)
    raise InputError(f"damaged after {held:,} of its {count:,} points ({why}){hint}",
                     file=path)


@contextmanager
def _laspy_quiet() -> Iterator[None]:
    """laspy logs a backend that fails and a short read as errors; both are said here in one
    line of our own, so its records are kept from the console."""
    logger = logging.getLogger("laspy")
    before = logger.propagate, logger.level
    logger.propagate, logger.level = False, logging.CRITICAL + 1
    try:
        yield
    finally:
        logger.propagate, logger.level = before


def _read_copc(path: Path, found: Layout, keep: int, request: ReadRequest) -> Cloud:
    """The coarse levels of a COPC octree, down to the deepest whose points (with all above
    it) number at most ``keep``: the cloud thinned evenly in space, the rest never read."""
    import laspy
    from laspy.copc import load_octree_for_query

    with _laspy_quiet(), laspy.CopcReader.open(str(path)) as copc:
        nodes = load_octree_for_query(copc.source, copc.copc_info, copc.root_page)
        per_level: dict[int, int] = {}
        for node in nodes:
            per_level[node.key.level] = per_level.get(node.key.level, 0) + node.point_count
        levels, total = 0, 0
        for level in sorted(per_level):
            if total + per_level[level] > keep and levels:
                break
            total += per_level[level]
            levels = level + 1
        names = set(copc.header.point_format.dimension_names)
        points = _Points(total, 1, {"red", "green", "blue"} <= names, "classification" in names)
        points.header = copc.header
        for level in range(levels):
            points.add(copc.query(level=level))
            if request.progress is not None:
                request.progress(points.read, total)
        spacing = float(copc.copc_info.spacing) / 2 ** (levels - 1)
    cloud = points.cloud()
    cloud.held = found.count
    cloud.notes.append(f"COPC: read octree levels 0 to {levels - 1} of {max(per_level) + 1} "
                       f"({points.kept:,} of {found.count:,} points, spaced about "
                       f"{spacing:.3g} file units): within --max-points {keep:,}")
    return cloud


def _las_crs(header: Any) -> str | None:
    """The header's coordinate system as WKT (from its WKT or GeoTIFF keys, by laspy and
    pyproj), or None."""
    try:
        crs = header.parse_crs()
    except Exception:  # keys or WKT pyproj cannot read: no georeference
        return None
    return None if crs is None else str(crs.to_wkt())


def _las_units(header: Any) -> tuple[float | None, float | None, str]:
    """Metres per horizontal and vertical unit from the GeoTIFF keys, else the WKT."""
    for vlr in header.vlrs:
        keys = {k.id: k.value_offset for k in getattr(vlr, "geo_keys", [])}
        if PROJ_LINEAR_UNITS in keys and keys[PROJ_LINEAR_UNITS] in LINEAR_UNITS:
            name, scale = LINEAR_UNITS[keys[PROJ_LINEAR_UNITS]]
            vertical = LINEAR_UNITS.get(keys.get(VERTICAL_UNITS, -1), (None, None))[1]
            return (scale, vertical, f"{name} (EPSG {keys[PROJ_LINEAR_UNITS]}, "
                    "from the header's GeoTIFF keys)")
    for vlr in header.vlrs:
        text = getattr(vlr, "string", None)
        if isinstance(text, bytes):
            text = text.decode("ascii", "replace")
        if not isinstance(text, str):
            continue
        linear = [(n, float(f)) for n, f in _WKT_UNIT.findall(text)
                  if not any(a in n.lower() for a in _ANGULAR)]
        if linear:
            name, scale = linear[0]
            vertical = linear[1][1] if len(linear) > 1 else None
            return scale, vertical, f"{name} ({scale:g} m, from the header's WKT)"
    return None, None, ""
