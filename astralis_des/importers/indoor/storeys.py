"""The storeys of an indoor point cloud: each one's floor level, ceiling and height.

The cloud is cut into vertical columns (``COLUMN`` square in plan). In each column the points,
sorted by height, leave gaps where nothing was seen: a gap of at least ``MIN_CLEAR`` closed by a
point above it is a storey's free height, its bottom an upward surface (a floor) and its top a
downward one (a ceiling). So a slab seen from both sides gives the ceiling of the storey under
it and the floor of the one over it, a roof seen from above is no floor (nothing closes the gap
over it), and neither is a floor seen under a table (the table's top closes that gap early).

The floors' heights, weighted by the area of the columns that see them, make a histogram
whose peaks are the storeys: taken highest first, at least ``MIN_STOREY`` apart, each covering
at least ``MIN_SHARE`` of the largest and ``MIN_AREA``. A stair's steps, a table top or a
window sill cover too little to count. Each floor's level is then the median height of the
points within ``BAND`` of its peak, and likewise its ceiling's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from astralis_des.world.geometry import FloatArray

COLUMN = 0.25  # m, the columns' side in plan
BIN = 0.05  # m, the floors' histogram
MIN_CLEAR = 1.9  # m, the least free height over a floor (over a table top there may be more)
MIN_STOREY = 2.2  # m, the least floor-to-floor height
MIN_SHARE = 0.15  # of the largest floor's area, the least a storey's floor covers
MIN_AREA = 4.0  # m², likewise
BAND = 0.1  # m either side of a peak: the points whose median is the level
HORIZONTAL = 0.9  # |n_z| of a point on a horizontal surface, when the cloud has normals


@dataclass(frozen=True)
class Storey:
    """A storey: its floor's height ``z``, its ``ceiling`` (the underside of what is over it)
    and its ``height`` floor to floor (the top storey's: its ceiling plus the slabs' median
    thickness)."""

    index: int  # 1 for the lowest
    z: float
    ceiling: float
    height: float
    area: float  # m² of floor the cloud saw

    @property
    def clear(self) -> float:
        """Floor to ceiling."""
        return self.ceiling - self.z


def find_storeys(points: FloatArray, normals: FloatArray | None = None) -> list[Storey]:
    """The storeys of an ``(N, 3)`` cloud (metres, z up), lowest first; none when no column
    holds a gap of ``MIN_CLEAR`` closed above."""
    xyz = np.asarray(points, dtype=float)
    if normals is not None:
        xyz = xyz[np.abs(np.asarray(normals, dtype=float)[:, 2]) >= HORIZONTAL]
    if len(xyz) < 2:
        return []
    bottoms, tops = _gaps(xyz)
    if not len(bottoms):
        return []
    peaks, weights = _peaks(bottoms)
    levels = sorted(zip(peaks, weights, strict=True))
    z = xyz[:, 2]
    floors, ceilings, areas = [], [], []
    for peak, weight in levels:
        level = _median_near(z, peak)
        mine = np.abs(bottoms - peak) <= BAND
        above = float(np.median(tops[mine]))
        floors.append(level)
        ceilings.append(_median_near(z, above))
        areas.append(weight * COLUMN**2)
    slabs = [floors[k + 1] - ceilings[k] for k in range(len(floors) - 1)
             if floors[k + 1] > ceilings[k]]
    slab = float(np.median(slabs)) if slabs else 0.0
    out = []
    for k, (zf, zc, area) in enumerate(zip(floors, ceilings, areas, strict=True)):
        top = floors[k + 1] if k + 1 < len(floors) else zc + slab
        out.append(Storey(k + 1, round(zf, 3), round(min(zc, top), 3), round(top - zf, 3),
                          round(area, 1)))
    return out


def _gaps(xyz: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The bottom and top heights of every free gap of ``MIN_CLEAR`` or more in a column."""
    lo = xyz[:, :2].min(axis=0)
    cells = np.floor((xyz[:, :2] - lo) / COLUMN).astype(np.int64)
    key = cells[:, 0] * (int(cells[:, 1].max()) + 1) + cells[:, 1]
    order = np.lexsort((xyz[:, 2], key))
    z, key = xyz[order, 2], key[order]
    gap = (key[1:] == key[:-1]) & (np.diff(z) >= MIN_CLEAR)
    at = np.flatnonzero(gap)
    return z[at], z[at + 1]


def _peaks(bottoms: FloatArray) -> tuple[list[float], list[float]]:
    """The histogram's peaks that are storeys' floors, and their weights (columns)."""
    lo = math.floor(bottoms.min() / BIN) * BIN
    index = np.floor((bottoms - lo) / BIN).astype(np.int64)
    counts = np.bincount(index).astype(float)
    # a floor's heights straddle two bins as often as not: count each bin with its neighbours
    smooth = np.convolve(counts, np.ones(3), mode="same")
    floor_cells = max(MIN_AREA / COLUMN**2, 1.0)
    order = np.argsort(-smooth, kind="stable")
    taken: list[int] = []
    for b in order:
        if smooth[b] < max(MIN_SHARE * smooth[order[0]], floor_cells):
            break
        if all(abs(int(b) - t) * BIN >= MIN_STOREY for t in taken):
            taken.append(int(b))
    return [lo + (b + 0.5) * BIN for b in taken], [float(smooth[b]) for b in taken]


def _median_near(z: NDArray[np.float64], level: float) -> float:
    near = z[np.abs(z - level) <= BAND]
    return float(np.median(near)) if len(near) else level
