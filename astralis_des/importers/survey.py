"""A cloud in the world's metres, chunk by chunk, and what a first look at it finds: which
points are usable (finite, not strays), their bounds, their spacing and their classes.

Each pass over the points converts one chunk at a time from the file's coordinates, so the
import holds the file's own numbers and small per-point flags, never a float64 copy of the
cloud. Longitude and latitude are projected once and kept as float32 offsets.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from astralis_des.errors import InputError
from astralis_des.importers.crs import Frame, frame_for
from astralis_des.importers.density import GAP_XY, GAP_Z, SAMPLE, Strays, spacing
from astralis_des.importers.ground import GROUND_CLASS
from astralis_des.importers.indoor.heading import turned
from astralis_des.importers.source import Cloud
from astralis_des.world.geometry import FloatArray

CHUNK = 1 << 20  # points converted at a time
FARTHEST = 1e8  # m: no coordinate system puts a place on the Earth further out
BoolArray = NDArray[np.bool_]


class Metres:
    """``cloud`` in the metres of ``frame`` (times ``scale``), a chunk at a time."""

    def __init__(self, cloud: Cloud, frame: Frame, scale: float) -> None:
        self.cloud = cloud
        self.frame = replace(frame, horizontal=frame.horizontal * scale,
                             vertical=frame.vertical * scale)
        self.scale = scale
        self.projected: NDArray[np.float32] | None = None
        self.origin = np.zeros(3)
        self.turn: tuple[float, FloatArray] | None = None  # radians about a pivot (xy)
        if frame.projection is not None:
            self._project()

    def _project(self) -> None:
        """Longitude and latitude onto the plane once (pyproj costs more than a pass)."""
        n = len(self.cloud)
        self.projected = np.empty((n, 3), dtype=np.float32)
        for lo in range(0, n, CHUNK):
            m = self.frame.metres(self.cloud.coordinates(lo, min(lo + CHUNK, n)))
            m[:, :2] *= self.scale
            if lo == 0:
                finite = m[np.isfinite(m).all(axis=1)]
                self.origin = np.floor(finite.min(axis=0)) if len(finite) else np.zeros(3)
            self.projected[lo:lo + len(m)] = m - self.origin

    def at(self, lo: int, hi: int) -> FloatArray:
        """Rows ``lo:hi`` in metres, float64 (turned, when :attr:`turn` says)."""
        if self.projected is not None:
            m = self.projected[lo:hi].astype(np.float64) + self.origin
        else:
            m = self.frame.metres(self.cloud.coordinates(lo, hi))
        return m if self.turn is None else turn_about(m, *self.turn)

    def chunks(self) -> Iterator[tuple[int, int, FloatArray]]:
        n = len(self.cloud)
        for lo in range(0, n, CHUNK):
            hi = min(lo + CHUNK, n)
            yield lo, hi, self.at(lo, hi)


@dataclass
class Survey:
    """What the first passes over a cloud found."""

    metres: Metres
    keep: BoolArray  # (N,) finite and not a stray
    kept: int
    dropped: int  # with NaN or infinite coordinates
    strays: int
    lo: FloatArray  # (3,) bounds of the kept points, metres
    hi: FloatArray
    spacing: float  # m between points, on average
    area: float  # m^2 the points cover
    ground_class: int  # kept points of class 2
    notes: list[str] = field(default_factory=list)


def survey(cloud: Cloud, units: str, crs: str | None, scale: float,
           keep_strays: bool) -> Survey:
    """Finite points, the frame, the strays left out, the bounds and the spacing."""
    n = len(cloud)
    finite = np.zeros(n, dtype=bool)
    lo_f, hi_f = np.full(3, np.inf), np.full(3, -np.inf)
    for lo in range(0, n, CHUNK):
        xyz = cloud.coordinates(lo, min(lo + CHUNK, n))
        ok = np.isfinite(xyz).all(axis=1)
        finite[lo:lo + len(xyz)] = ok
        if ok.any():
            lo_f = np.minimum(lo_f, xyz[ok].min(axis=0))
            hi_f = np.maximum(hi_f, xyz[ok].max(axis=0))
    count = int(finite.sum())
    if not count:
        raise InputError(f"no point has finite coordinates ({n:,} dropped)")
    metres = Metres(cloud, frame_for(cloud, units, crs, lo_f, hi_f), scale)
    _on_earth(metres, lo_f, hi_f)
    sample = _sample_rows(finite, SAMPLE)
    space, _ = spacing(_gather(metres, sample)[:, :2], count)
    keep, notes = finite, []
    if not keep_strays and count > 1:
        strays = Strays((max(GAP_XY[0], GAP_XY[1] * space),) * 2 + (max(GAP_Z, 2 * space),))
        for lo, hi, m in metres.chunks():
            strays.add(m[finite[lo:hi]])
        notes = strays.decide(count)
        if notes:
            keep = finite.copy()
            for lo, hi, m in metres.chunks():
                keep[lo:hi] &= strays.keep(m)
    kept = int(keep.sum())
    lo_m, hi_m = np.full(3, np.inf), np.full(3, -np.inf)
    for lo, hi, m in metres.chunks():
        rows = m[keep[lo:hi]]
        if len(rows):
            lo_m, hi_m = np.minimum(lo_m, rows.min(axis=0)), np.maximum(hi_m, rows.max(axis=0))
    if kept < count:
        sample = _sample_rows(keep, SAMPLE)
        space, _ = spacing(_gather(metres, sample)[:, :2], kept)
    area = space * space * kept
    classes = cloud.classification
    ground_class = int(np.count_nonzero(classes[keep] == GROUND_CLASS)) \
        if classes is not None else 0
    return Survey(metres, keep, kept, n - count, count - kept, lo_m, hi_m, space, area,
                  ground_class, notes)


def turn_about(points: FloatArray, angle: float, pivot: FloatArray) -> FloatArray:
    """``(N, 3)`` points turned by ``angle`` radians (anticlockwise) about the vertical line
    through ``pivot`` (xy): :func:`.indoor.heading.turned` about it."""
    shift = np.zeros(points.shape[1])
    shift[:2] = np.asarray(pivot, dtype=np.float64)[:2]
    return np.asarray(turned(np.asarray(points, dtype=np.float64) - shift, angle) + shift)


def turned_survey(found: Survey, angle: float) -> Survey:
    """``found`` with its points turned by ``angle`` radians about the middle of their
    bounds: the bounds found anew (the spacing, the strays and the classes are the same)."""
    pivot = (found.lo[:2] + found.hi[:2]) / 2
    found.metres.turn = (angle, pivot)
    lo_m, hi_m = np.full(3, np.inf), np.full(3, -np.inf)
    for lo, hi, m in found.metres.chunks():
        rows = m[found.keep[lo:hi]]
        if len(rows):
            lo_m, hi_m = np.minimum(lo_m, rows.min(axis=0)), np.maximum(hi_m, rows.max(axis=0))
    return replace(found, lo=lo_m, hi=hi_m)


def sample(found: Survey, size: int) -> FloatArray:
    """At most ``size`` of the kept points, in metres, spread evenly through the file."""
    return _gather(found.metres, _sample_rows(found.keep, size))


def _on_earth(metres: Metres, lo: FloatArray, hi: FloatArray) -> None:
    """Coordinates beyond ``FARTHEST`` metres are no place on the Earth: a header's scale or
    offset is wrong, or the units are."""
    if metres.frame.projection is not None:
        return  # longitude and latitude were checked when the plane was made
    with np.errstate(over="ignore", invalid="ignore"):
        corners = metres.frame.metres(np.array([lo, hi]))
    far = float(np.abs(corners).max())
    if not np.isfinite(far) or far > FARTHEST:
        raise InputError(f"coordinates reach {far:.3g} m, no place on the Earth: check the "
                         "file's scale and offset, or its units (--units, --crs)")


def _sample_rows(mask: BoolArray, size: int) -> NDArray[np.int64]:
    """Rows of ``mask`` spread evenly through the file, at most ``size``."""
    rows = np.flatnonzero(mask)
    if len(rows) <= size:
        return rows
    return rows[np.linspace(0, len(rows) - 1, size).astype(np.int64)]


def _gather(metres: Metres, rows: NDArray[np.int64]) -> FloatArray:
    """The metres of ``rows`` (sorted), chunk by chunk."""
    out = np.empty((len(rows), 3))
    n = len(metres.cloud)
    for lo in range(0, n, CHUNK):
        hi = min(lo + CHUNK, n)
        a, b = np.searchsorted(rows, [lo, hi])
        if b > a:
            out[a:b] = metres.at(lo, hi)[rows[a:b] - lo]
    return out
