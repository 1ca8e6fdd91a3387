"""The squared distance field of a voxel map built from boxes, one horizontal layer at a time.

A box's occupied cells are a product of three index ranges, so the distance to it is separable,
and the distance to all boxes is the minimum over them. Each box is swept only over the cells
it could be nearest to: closer than a box covering the whole map (the ground) is, layer by
layer. A layer is made when a query first reads it: a run asks about the heights its robots
fly and drive at, a few of the dozens of layers (the default world's map is 65 layers, 125 MB
and a third of a second made whole).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

IntArray = NDArray[np.intp]
Squared = NDArray[np.unsignedinteger]


def gaps(first: IntArray | int, stop: IntArray | int, index: IntArray) -> IntArray:
    """Cells between ``index`` and the range ``first <= i < stop`` (0 inside it)."""
    return np.maximum(np.maximum(first - index, index - (stop - 1)), 0)


class Layers:
    """``(nx, ny)`` squared distances in cells to the nearest cell of any box, per layer ``k``.

    Box ``b`` occupies cells ``first[b] <= index < stop[b]``.
    """

    def __init__(self, first: IntArray, stop: IntArray, shape: tuple[int, int, int]) -> None:
        nx, ny, nz = shape
        self.first, self.stop, self.shape = first, stop, shape
        self.gap_z = gaps(first[:, 2, None], stop[:, 2, None], np.arange(nz))  # (K, nz)
        covers = np.all(first[:, :2] == 0, axis=1) & np.all(stop[:, :2] == (nx, ny), axis=1)
        # No cell is farther from its nearest box than from a box covering every column.
        self.reach = self.gap_z[covers].min(axis=0) if covers.any() else \
            np.full(nz, math.ceil(math.hypot(nx, ny, nz)))
        self.dtype: type[np.unsignedinteger] = \
            np.uint16 if 3 * int(self.reach.max()) ** 2 < np.iinfo(np.uint16).max else np.uint32
        self.made: dict[int, Squared] = {}

    def layer(self, k: int) -> Squared:
        """Layer ``k``, made the first time it is asked for."""
        if k not in self.made:
            self.made[k] = self._make(k)
        return self.made[k]

    def _make(self, k: int) -> Squared:
        nx, ny, _ = self.shape
        dtype, reach, gz = self.dtype, int(self.reach[k]), self.gap_z[:, k]
        d2 = np.full((nx, ny), np.iinfo(dtype).max, dtype)
        ix, iy = np.arange(nx), np.arange(ny)
        for b in np.flatnonzero(gz <= reach).tolist():
            (i0, j0, _), (i1, j1, _) = self.first[b].tolist(), self.stop[b].tolist()
            w = math.isqrt(reach ** 2 - int(gz[b]) ** 2)
            xa, xb, ya, yb = max(i0 - w, 0), min(i1 + w, nx), max(j0 - w, 0), min(j1 + w, ny)
            gx: NDArray[Any] = gaps(i0, i1, ix[xa:xb]).astype(dtype)
            gy: NDArray[Any] = gaps(j0, j1, iy[ya:yb]).astype(dtype)
            window = d2[xa:xb, ya:yb]
            np.minimum(window, (gx * gx + dtype(gz[b] ** 2))[:, None] + (gy * gy)[None, :],
                       out=window)
        return d2

    def whole(self) -> Squared:
        """Every layer, as one ``(nx, ny, nz)`` view of layer-major memory."""
        nx, ny, nz = self.shape
        d2 = np.empty((nz, nx, ny), self.dtype)
        for k in range(nz):
            d2[k] = self.layer(k)
        self.made = {k: d2[k] for k in range(nz)}  # the layers' own copies freed
        return d2.transpose(1, 2, 0)


class LayerField:
    """Lookups in :class:`Layers` (``convert``: squared cells to metres, as on the whole
    field: the same numbers); 0 for cells outside the field."""

    def __init__(self, layers: Layers, convert: Callable[[Squared], NDArray[np.float32]]) -> None:
        self.layers, self.convert = layers, convert
        self.shape = np.array(layers.shape)

    def at(self, cells: IntArray) -> NDArray[np.float64]:
        inside = ((cells >= 0) & (cells < self.shape)).all(axis=1)
        values = np.zeros(len(cells))
        ks = cells[inside, 2]
        if not len(ks):
            return values
        for k in np.unique(ks).tolist():
            rows = np.flatnonzero(inside)[ks == k]
            taken = self.layers.layer(k)[cells[rows, 0], cells[rows, 1]]
            values[rows] = self.convert(taken).astype(float)
        return values
