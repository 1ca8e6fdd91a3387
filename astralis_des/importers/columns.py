"""An aerial scan's columns: each voxel column of the site solid from the ground up to its
highest point (an aerial scanner sees the roof, not what is under it).

The highest point of each column is folded in chunk by chunk: in a grid when the site's grid
is small (at most ``COLUMN_GRID`` cells), else by the columns' keys, so that a kilometre-wide
site at a fine voxel costs what its points hold. A grey closing of ``size`` cells fills the
holes that the scan's spacing leaves between the columns of one roof; on a large site it runs
tile by tile over the tiles that hold points.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from astralis_des.importers.sparse import IntArray, Keyed, pack, unpack
from astralis_des.world.geometry import FloatArray

TILE = 1024  # cells a side of a tile of the closing
COLUMN_GRID = 1 << 24  # cells of the largest grid of columns (16 M: 128 MB)


class Columns:
    """The highest point above the ground of each ``(i, j)`` column."""

    def __init__(self, shape: tuple[int, int]) -> None:
        self.shape = shape
        self.grid = np.zeros(shape) if math.prod(shape) <= COLUMN_GRID else None
        self.keyed = Keyed("max")

    def add(self, cells: IntArray, heights: FloatArray) -> None:
        if self.grid is not None:
            np.maximum.at(self.grid, (cells[:, 0], cells[:, 1]), heights)
        else:
            self.keyed.add(pack(cells), heights)

    def tops(self, voxel: float, size: int) -> tuple[IntArray, IntArray, NDArray[np.int32]]:
        """``(i, j, top)`` of the columns, closed by ``size`` cells, ``top`` in voxels."""
        if self.grid is not None:
            grid = ndimage.grey_closing(self.grid, size=(size, size)) if size > 1 else \
                self.grid
            i, j = np.nonzero(grid > 0)
            heights = grid[i, j]
        else:
            keys, heights = self.keyed.result()
            index = unpack(keys, 2)
            i, j = index[:, 0], index[:, 1]
            if size > 1:
                i, j, heights = _closed_by_tiles(i, j, heights, self.shape, size)
        top = np.ceil(heights / voxel - 1e-6).astype(np.int32)
        return i.astype(np.int64), j.astype(np.int64), top


def _closed_by_tiles(i: IntArray, j: IntArray, heights: FloatArray, shape: tuple[int, int],
                     size: int) -> tuple[IntArray, IntArray, FloatArray]:
    """A grey closing of the sparse columns, tile by tile: each tile that holds columns, or
    touches one that does, is closed with a halo of ``size`` cells around it."""
    halo = size
    ti, tj = i // TILE, j // TILE
    stride = shape[1] // TILE + 2
    near: set[tuple[int, int]] = set()
    for a in (-1, 0, 1):  # a column within the halo of a tile's edge closes into that tile too
        for b in (-1, 0, 1):
            reach = (((i % TILE < halo) if a < 0 else (i % TILE >= TILE - halo)) if a else
                     np.ones(len(i), dtype=bool)) & \
                (((j % TILE < halo) if b < 0 else (j % TILE >= TILE - halo)) if b else True)
            keys = np.unique((ti[reach] + a) * stride + tj[reach] + b)
            near.update((int(k // stride), int(k % stride)) for k in keys)
    order = np.lexsort((tj, ti))
    flat = ti[order] * stride + tj[order]
    found: list[tuple[IntArray, IntArray, FloatArray]] = []
    for a, b in sorted(near):
        if a < 0 or b < 0 or a * TILE >= shape[0] or b * TILE >= shape[1]:
            continue
        lo_i, lo_j = a * TILE - halo, b * TILE - halo
        grid = np.zeros((TILE + 2 * halo, TILE + 2 * halo))
        for da in (-1, 0, 1):
            for db in (-1, 0, 1):
                key = (a + da) * stride + b + db
                rows = order[np.searchsorted(flat, key):np.searchsorted(flat, key, "right")]
                u, v = i[rows] - lo_i, j[rows] - lo_j
                ok = (u >= 0) & (u < grid.shape[0]) & (v >= 0) & (v < grid.shape[1])
                np.maximum.at(grid, (u[ok], v[ok]), heights[rows][ok])
        inner = ndimage.grey_closing(grid, size=(size, size))[halo:halo + TILE,
                                                               halo:halo + TILE]
        u, v = np.nonzero(inner > 0)
        keep = (u + a * TILE < shape[0]) & (v + b * TILE < shape[1])
        found.append((u[keep] + a * TILE, v[keep] + b * TILE, inner[u[keep], v[keep]]))
    if not found:
        return i, j, heights
    return (np.concatenate([f[0] for f in found]), np.concatenate([f[1] for f in found]),
            np.concatenate([f[2] for f in found]))
