"""Round or over an imported world's blocks: the legs of a route that cross a building, a tree
or a wall of a digital twin.

The room graph leaves blocks out (a scan has thousands), so a leg that crosses one is replaced
here, in both fidelities: walkers and the UGV go round on a 2-D grid of the heights they
occupy; a UAV goes round at its altitude, or climbs over (its clearance plus ``CLIMB`` above
the highest block under the leg), whichever is shorter. Searches are Dijkstra on the grid
(scipy), bounded in distance, never in wall time: the same mission gives the same routes.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from astralis_des.memo import kept
from astralis_des.world.geometry import FloatArray, polyline_length, segments_hit_boxes
from astralis_des.world.model import World

CELL_MIN = 0.5  # m: the grid is the world's voxel, or this if the voxel is finer
CLIMB = 1.0  # m above the highest block under a leg that a UAV flies over
DETOUR_FACTOR = 3.0  # a way round is searched up to this times the straight leg, plus SLACK
SLACK = 30.0  # m
WALK_BAND = (0.05, 1.8)  # m above the floor that a walker or the UGV occupies
MARGIN = 0.5  # m kept from blocks beyond the body: a scan's voxels are rough, a craft sways
_STEPS = ((1, 0), (0, 1), (1, 1), (1, -1))


@dataclass(frozen=True, eq=False)
class _Band:
    """The grid of one height band: free cells (for a radius) and their graph."""

    free: NDArray[np.bool_]
    graph: csr_matrix


class BlockField:
    """The blocks of one world, and the grids of the bands asked for so far."""

    def __init__(self, world: World) -> None:
        self.blocks = world.block_array
        self.cell = max(world.map_resolution, CELL_MIN)
        self.shape = (max(math.ceil(world.site[0] / self.cell), 1),
                      max(math.ceil(world.site[1] / self.cell), 1))
        self._bands: dict[tuple[int, int, int], _Band] = {}
        self._grown_by: dict[int, FloatArray] = {}

    def crosses(self, a: FloatArray, b: FloatArray, radius: float) -> bool:
        """Does the leg pass within ``radius`` of a block?"""
        return bool(segments_hit_boxes(a[None, :], b[None, :], self._grown(radius))[0])

    def _grown(self, radius: float) -> FloatArray:
        key = round(radius * 1000)
        if key not in self._grown_by:
            self._grown_by[key] = np.stack([self.blocks[:, 0] - radius,
                                            self.blocks[:, 1] + radius], axis=1)
        return self._grown_by[key]

    def around(self, a: FloatArray, b: FloatArray, radius: float, z_lo: float,
               z_hi: float) -> FloatArray | None:
        """A way from ``a`` to ``b`` through the cells free between ``z_lo`` and ``z_hi``; its
        height goes evenly from ``a``'s to ``b``'s."""
        band = self._band(z_lo, z_hi, radius)
        start, goal = self._free_cell(band, a), self._free_cell(band, b)
        if start is None or goal is None:
            return None
        limit = DETOUR_FACTOR * float(np.linalg.norm(b[:2] - a[:2])) + SLACK
        flat = np.ravel_multi_index(start, self.shape), np.ravel_multi_index(goal, self.shape)
        dist, pred = dijkstra(band.graph, indices=int(flat[0]), limit=limit,
                              return_predecessors=True)
        if not np.isfinite(dist[flat[1]]):
            return None
        cells = [int(flat[1])]
        while cells[-1] != flat[0]:
            cells.append(int(pred[cells[-1]]))
        ij = np.column_stack(np.unravel_index(np.array(cells[::-1]), self.shape))
        xy = np.vstack([a[:2], (ij + 0.5) * self.cell, b[:2]])
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
        z = a[2] + (b[2] - a[2]) * (s / s[-1] if s[-1] > 0 else s)
        return self._smooth(np.column_stack([xy, z]), radius, z_lo, z_hi)

    def _smooth(self, points: FloatArray, radius: float, z_lo: float,
                z_hi: float) -> FloatArray:
        """Keep only the turns: drop every point that a straight line clear of the band's
        blocks (grown by ``radius``, tested exactly, not on the grid) can skip."""
        grown = self._grown(radius)
        grown = grown[(grown[:, 0, 2] < z_hi) & (grown[:, 1, 2] > z_lo)]
        flat = _flat(grown)
        kept, i = [0], 0
        while i < len(points) - 1:
            j = len(points) - 1
            while j > i + 1 and segments_hit_boxes(points[i:i + 1], points[j:j + 1], flat)[0]:
                j -= 1
            kept.append(j)
            i = j
        return points[kept]

    def over(self, a: FloatArray, b: FloatArray, radius: float) -> FloatArray | None:
        """Up from ``a``, across ``radius`` + ``CLIMB`` above the highest block the leg
        crosses, down to ``b``; ``None`` if something stands above either end."""
        grown = self._grown(radius)
        lo = np.minimum(a[:2], b[:2]) - radius
        hi = np.maximum(a[:2], b[:2]) + radius
        under = np.all((grown[:, 0, :2] <= hi) & (grown[:, 1, :2] >= lo), axis=1)
        crossed = grown[under][segments_hit_boxes(
            np.repeat(np.array([[a[0], a[1], -1.0]]), int(under.sum()), 0),
            np.repeat(np.array([[b[0], b[1], -1.0]]), int(under.sum()), 0),
            _flat(grown[under]))] if under.any() else grown[:0]
        top = max(float(crossed[:, 1, 2].max()) if len(crossed) else 0.0, a[2], b[2]) + CLIMB
        path = np.array([a, [a[0], a[1], top], [b[0], b[1], top], b])
        hits = segments_hit_boxes(path[:-1], path[1:], grown)
        return None if hits.any() else path

    def _band(self, z_lo: float, z_hi: float, radius: float) -> _Band:
        key = (math.floor(z_lo / self.cell), math.ceil(z_hi / self.cell),
               round(radius * 100))
        if key not in self._bands:
            self._bands[key] = self._make_band(key[0] * self.cell, key[1] * self.cell, radius)
        return self._bands[key]

    def _make_band(self, z_lo: float, z_hi: float, radius: float) -> _Band:
        blocked = np.zeros(self.shape, dtype=bool)
        boxes = self.blocks[(self.blocks[:, 0, 2] < z_hi) & (self.blocks[:, 1, 2] > z_lo)]
        first = np.floor(boxes[:, 0, :2] / self.cell + 1e-6).astype(np.int64)
        stop = np.ceil(boxes[:, 1, :2] / self.cell - 1e-6).astype(np.int64)
        first, stop = np.clip(first, 0, self.shape), np.clip(stop, 0, self.shape)
        for (i0, j0), (i1, j1) in zip(first.tolist(), stop.tolist(), strict=True):
            blocked[i0:i1, j0:j1] = True
        clearance = ndimage.distance_transform_edt(~blocked) * self.cell if blocked.any() \
            else np.full(self.shape, np.inf)
        free = clearance > radius + self.cell / 2
        return _Band(free, _grid_graph(free, self.cell))

    def _free_cell(self, band: _Band, p: FloatArray) -> tuple[int, int] | None:
        """The cell of ``p``, or the nearest free one within two cells."""
        i, j = (int(v) for v in np.floor(p[:2] / self.cell))
        best, best_d = None, math.inf
        for di in range(-2, 3):
            for dj in range(-2, 3):
                ni, nj = i + di, j + dj
                if 0 <= ni < self.shape[0] and 0 <= nj < self.shape[1] and band.free[ni, nj] \
                        and di * di + dj * dj < best_d:
                    best, best_d = (ni, nj), di * di + dj * dj
        return best


def block_field(world: World) -> BlockField:
    """The world's block field, made once and kept with the world."""
    cache: dict[str, BlockField] = kept(world, "block_field")
    if "field" not in cache:
        cache["field"] = BlockField(world)
    return cache["field"]


def round_blocks(world: World, points: FloatArray, radius: float, *, fly: bool,
                 floor: float) -> tuple[FloatArray | None, str]:
    """``points`` with every leg that crosses a block replaced by the shorter of going round
    and (flying) going over: ``(path, "")``, or ``(None, reason)``."""
    field = block_field(world)
    radius += MARGIN
    out = [points[0]]
    for a, b in itertools.pairwise(points):
        if not field.crosses(a, b, radius):
            out.append(b)
            continue
        z_lo, z_hi = ((min(a[2], b[2]) - radius, max(a[2], b[2]) + radius) if fly else
                      (floor + WALK_BAND[0], floor + WALK_BAND[1]))
        ways = [w for w in (field.around(a, b, radius, z_lo, z_hi),
                            field.over(a, b, radius) if fly else None) if w is not None]
        if not ways:
            where = ", ".join(f"{v:.1f}" for v in b)
            return None, f"no way round the blocks to [{where}]"
        best = min(ways, key=polyline_length)
        out.extend(best[1:])
    return np.array(out), ""


def _flat(boxes: FloatArray) -> FloatArray:
    """Boxes stretched over all heights (their footprints), for a test in plan."""
    flat = boxes.copy()
    flat[:, 0, 2], flat[:, 1, 2] = -np.inf, np.inf
    return flat


def _grid_graph(free: NDArray[np.bool_], cell: float) -> csr_matrix:
    """8-connected graph of the free cells (diagonals only between two free neighbours)."""
    nx, ny = free.shape
    index = np.arange(nx * ny).reshape(nx, ny)
    rows, cols, weights = [], [], []
    for di, dj in _STEPS:
        a = free[max(-di, 0):nx - max(di, 0), max(-dj, 0):ny - max(dj, 0)]
        b = free[max(di, 0):nx + min(di, 0) or None, max(dj, 0):ny + min(dj, 0) or None]
        ok = a & b
        if di and dj:
            side1 = free[max(di, 0):nx + min(di, 0) or None, max(-dj, 0):ny - max(dj, 0)]
            side2 = free[max(-di, 0):nx - max(di, 0), max(dj, 0):ny + min(dj, 0) or None]
            ok &= side1 & side2
        ia = index[max(-di, 0):nx - max(di, 0), max(-dj, 0):ny - max(dj, 0)][ok]
        ib = index[max(di, 0):nx + min(di, 0) or None, max(dj, 0):ny + min(dj, 0) or None][ok]
        rows += [ia, ib]
        cols += [ib, ia]
        weights += [np.full(len(ia), cell * math.hypot(di, dj))] * 2
    return csr_matrix((np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(nx * ny, nx * ny))
