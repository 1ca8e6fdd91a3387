"""How dense a cloud is, what voxel fits it, and which of its points stray far from the rest.

The point spacing is the square root of the ground each point covers: the area of the cells
holding points, at the finest cell size that holds four points a cell on average, over the
points. It is measured on an even sample (the area a cloud covers does not depend on how many
of its points are looked at) and so costs the same for a thousand points or fifty million.

Strays: along each axis, the points are binned at a width of ``gap``; runs of occupied bins
separated by an empty one are clusters, and a cluster holding less than ``STRAY_SHARE`` of the
points is left out (a point 80 km from its tile, a bird 300 m above it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from astralis_des.importers.sparse import Keyed, runs
from astralis_des.world.geometry import FloatArray

SAMPLE = 200_000  # points the spacing is measured on
NICE = (0.2, 0.25, 0.5, 1.0, 2.0, 2.5, 5.0, 10.0)  # voxels to choose from, in metres
SPARSE = 1.0  # m: a cloud spaced wider than this is coarse (under one point per m^2)
STRAY_SHARE = 0.01  # a cluster with fewer of the points than this is left out
GAP_XY = (100.0, 50.0)  # m, and spacings: the emptiness that cuts a stray off, across
GAP_Z = 50.0  # m up or down
MAX_RASTER = 1 << 22  # cells in a 2-D grid over the site (4 M: 32 MB of float64)


def spacing(xy: FloatArray, points: int) -> tuple[float, float]:
    """The mean spacing (m) of a cloud of ``points`` of which ``xy`` is an even sample, and
    the area (m^2) its points cover."""
    if len(xy) < 2 or points < 2:
        return 0.0, 0.0
    span = np.ptp(xy, axis=0)
    if not span.any():
        return 0.0, 0.0
    cell = 2.0 ** math.floor(math.log2(max(math.sqrt(float(np.prod(np.maximum(span, 1e-3)))
                                                     / points) / 4, 1e-3)))
    lo = xy.min(axis=0)
    while True:
        index = np.floor((xy - lo) / cell).astype(np.int64)
        cells = len(np.unique(index[:, 0] * (int(index[:, 1].max()) + 1) + index[:, 1]))
        if len(xy) >= 4 * cells or cell > 2 * span.max():
            area = cells * cell * cell
            return math.sqrt(area / points), area
        cell *= 2


def choose_voxel(spacing_m: float) -> float:
    """The finest of the ``NICE`` voxels that is no finer than the points' spacing."""
    return next((v for v in NICE if v >= spacing_m - 1e-9), NICE[-1])


def nice_up(value: float) -> float:
    """``value`` rounded up to 1, 2 or 5 times a power of ten."""
    if value <= 0:
        return 1.0
    power = 10.0 ** math.floor(math.log10(value))
    return next(m * power for m in (1.0, 2.0, 5.0, 10.0) if m * power >= value - 1e-12)


def raster_cell(step: float, extent: FloatArray, cap: int = MAX_RASTER) -> float:
    """The finest multiple of ``step`` whose grid over ``extent`` (m, x and y) has at most
    ``cap`` cells."""
    cells = float(np.prod(np.maximum(np.asarray(extent, dtype=float) / step, 1.0)))
    return step * max(math.ceil(math.sqrt(cells / cap)), 1)


@dataclass
class Strays:
    """Points binned along x, y and z chunk by chunk; then the ranges to leave out."""

    widths: tuple[float, float, float]
    bins: list[Keyed] = field(default_factory=lambda: [Keyed("sum") for _ in range(3)])
    cut: list[list[tuple[float, float]]] = field(default_factory=lambda: [[], [], []])

    def add(self, xyz: FloatArray) -> None:
        for axis in range(3):
            keys = np.floor(xyz[:, axis] / self.widths[axis]).astype(np.int64)
            self.bins[axis].add(keys, np.ones(len(keys)))

    def decide(self, points: int) -> list[str]:
        """Settle which ranges are cut off; a line for each axis with strays."""
        said = []
        for axis, name in enumerate("xyz"):
            keys, counts = self.bins[axis].result()
            clusters = runs(keys)
            if len(clusters) < 2:
                continue
            held = [int(counts[(keys >= a) & (keys <= b)].sum()) for a, b in clusters]
            width = self.widths[axis]
            main = int(np.argmax(held))
            for (a, b), n in zip(clusters, held, strict=True):
                if n < STRAY_SHARE * points:
                    self.cut[axis].append((a * width, (b + 1) * width))
            if self.cut[axis]:
                lost = sum(n for (a, b), n in zip(clusters, held, strict=True)
                           if (a * width, (b + 1) * width) in self.cut[axis])
                far = max(max(abs(lo - clusters[main][1] * width),
                              abs(clusters[main][0] * width - hi))
                          for lo, hi in self.cut[axis])
                said.append(f"left out {lost:,} stray point{'s' * (lost != 1)} up to "
                            f"{far:,.0f} m from the rest along {name} (more than "
                            f"{width:,.0f} m of nothing between); --keep-strays keeps them")
        return said

    def keep(self, xyz: FloatArray) -> np.ndarray:
        """``(N,)``: not in a range that was cut off."""
        ok = np.ones(len(xyz), dtype=bool)
        for axis in range(3):
            for lo, hi in self.cut[axis]:
                ok &= ~((xyz[:, axis] >= lo) & (xyz[:, axis] < hi))
        return ok
