"""Voxel occupancy and its collision geometry: merged boxes.

Voxel ``(i, j, k)`` spans ``(i, j, k) * voxel`` to one voxel further, in the world frame (an
imported world's origin is its voxel grid's corner). Boxes are index ranges
``[i0, j0, k0, i1, j1, k1)``: runs along z, merged along y, then along x, all vectorised, so a
few million voxels merge in about a second. The merge is greedy, not minimal: a box is kept
whole only where whole runs line up.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from astralis_des.errors import InputError
from astralis_des.world.geometry import FloatArray

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

MAX_VOXELS = 400_000_000  # a dense grid larger than this (bytes) is refused, not attempted
MAX_INDEX = 65_535  # boxes are stored as uint16 indices


def _cells(length: float, voxel: float) -> int:
    return max(math.ceil(float(length) / voxel - 1e-9), 1)


def cells_across(extent: FloatArray, voxel: float) -> tuple[int, int]:
    """Voxels covering the first two axes of ``extent`` (metres)."""
    return _cells(extent[0], voxel), _cells(extent[1], voxel)


def grid_shape(extent: FloatArray, voxel: float, *, what: str = "the geometry") -> tuple[int, ...]:
    """Cells covering ``extent`` (metres per axis) at ``voxel``; refused when too many."""
    shape = tuple(_cells(e, voxel) for e in extent)
    cells = math.prod(shape)
    if cells > MAX_VOXELS or max(shape) > MAX_INDEX:
        smallest = voxel * max((cells / MAX_VOXELS) ** (1 / len(shape)),
                               max(shape) / MAX_INDEX)
        raise InputError(f"{what} spans {' x '.join(f'{float(e):.0f}' for e in extent)} m: "
                         f"{cells:,} voxels of {voxel:g} m are too many; pass --voxel "
                         f"{math.ceil(smallest * 10) / 10:g} or more", key="--voxel")
    return shape


def voxel_index(points: FloatArray, voxel: float) -> IntArray:
    """``(N, 3)`` voxel of each point; a point on a face belongs to the voxel below it, so a
    floor at a multiple of the voxel does not spill into the voxel above."""
    return np.floor(np.asarray(points) / voxel - 1e-6).astype(np.int64)


def unique_rows(index: IntArray) -> IntArray:
    """The distinct rows of ``(M, 3)`` integer indices, sorted (faster than ``unique(axis=0)``:
    one flat key a row)."""
    if len(index) == 0:
        return np.zeros((0, 3), dtype=np.int64)
    low = index.min(axis=0)
    dims = tuple(int(d) for d in index.max(axis=0) - low + 1)
    flat = np.unique(np.ravel_multi_index(tuple((index - low).T), dims))
    return np.column_stack(np.unravel_index(flat, dims)).astype(np.int64) + low


def boxes_from_columns(i: IntArray, j: IntArray, tops: NDArray[np.int32]) -> IntArray:
    """Merged boxes of columns ``(i, j)`` standing on ``k = 0`` up to ``tops`` voxels."""
    stand = tops > 0
    i, j, tops = i[stand], j[stand], tops[stand]
    runs = np.column_stack([i, j, j + 1, np.zeros_like(i), tops]).astype(np.int64)
    return _merge_x(_merge_y(runs))


def boxes_from_indices(cells: IntArray) -> IntArray:
    """Merged boxes of unique voxel indices ``(M, 3)``, in any order."""
    if len(cells) == 0:
        return np.zeros((0, 6), dtype=np.int64)
    cells = cells[np.lexsort((cells[:, 2], cells[:, 1], cells[:, 0]))]
    i, j, k = cells[:, 0], cells[:, 1], cells[:, 2]
    start = np.ones(len(cells), dtype=bool)
    start[1:] = (i[1:] != i[:-1]) | (j[1:] != j[:-1]) | (k[1:] != k[:-1] + 1)
    first = np.flatnonzero(start)
    last = np.append(first[1:], len(cells)) - 1
    runs = np.column_stack([i[first], j[first], j[first] + 1, k[first], k[last] + 1])
    return _merge_x(_merge_y(runs))


def _merge_y(runs: IntArray) -> IntArray:
    """z-runs ``(i, j, j + 1, k0, k1)`` side by side along y become ``(i, j0, j1, k0, k1)``."""
    if len(runs) == 0:
        return np.zeros((0, 5), dtype=np.int64)
    order = np.lexsort((runs[:, 1], runs[:, 4], runs[:, 3], runs[:, 0]))
    r = runs[order]
    same = np.zeros(len(r), dtype=bool)
    same[1:] = (r[1:, 0] == r[:-1, 0]) & (r[1:, 3] == r[:-1, 3]) & (r[1:, 4] == r[:-1, 4]) & \
        (r[1:, 1] == r[:-1, 2])
    first = np.flatnonzero(~same)
    last = np.append(first[1:], len(r)) - 1
    return np.column_stack([r[first, 0], r[first, 1], r[last, 2], r[first, 3], r[first, 4]])


def _merge_x(rects: IntArray) -> IntArray:
    """Rectangles ``(i, j0, j1, k0, k1)`` side by side along x become boxes
    ``[i0, j0, k0, i1, j1, k1)``."""
    if len(rects) == 0:
        return np.zeros((0, 6), dtype=np.int64)
    order = np.lexsort((rects[:, 0], rects[:, 4], rects[:, 3], rects[:, 2], rects[:, 1]))
    r = rects[order]
    same = np.zeros(len(r), dtype=bool)
    same[1:] = np.all(r[1:, 1:] == r[:-1, 1:], axis=1) & (r[1:, 0] == r[:-1, 0] + 1)
    first = np.flatnonzero(~same)
    last = np.append(first[1:], len(r)) - 1
    return np.column_stack([r[first, 0], r[first, 1], r[first, 3],
                            r[last, 0] + 1, r[first, 2], r[first, 4]])


def box_corners(boxes: IntArray, voxel: float) -> FloatArray:
    """``(K, 2, 3)`` corners in metres of index boxes."""
    b = np.asarray(boxes, dtype=float).reshape(-1, 6) * voxel
    return np.stack([b[:, :3], b[:, 3:]], axis=1)
