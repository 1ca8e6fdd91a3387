"""Occupancy of a world as a voxel map with a distance field, and 2-D slices of it.

A voxel is occupied when it overlaps a solid box, so a 0.2 m wall stays a whole wall at any
resolution. Cell ``(i, j, k)`` spans ``origin + (i, j, k) * resolution`` to one resolution
further. ``distance`` is the Euclidean distance in metres from a cell's centre to the nearest
occupied cell's centre: what ``scipy.ndimage.distance_transform_edt(~occupied,
sampling=resolution)`` gives (0 on occupied cells, inf when nothing is occupied).

The 3-D field is found from the boxes rather than by scipy, which takes 18 s for the 62 M voxels
of the default world, one horizontal layer at a time as queries reach it
(:mod:`astralis_des.planning.layers`).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property, partial
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from astralis_des.memo import kept
from astralis_des.planning.layers import LayerField, Layers
from astralis_des.world.geometry import FloatArray
from astralis_des.world.model import World

BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.intp]
A = TypeVar("A", bound=NDArray[Any])

GROUND_DEPTH = 0.4  # m of solid ground below z = 0
MANY_BOXES = 1000  # more boxes than this are rasterised, then distance-transformed
MAX_MAP_VOXELS = 40_000_000  # a rasterised map finer than this is coarsened
log = logging.getLogger(__name__)
_EPS = 1e-6  # in cells: a box that only touches a cell's face does not occupy it
_TIE = 1e-5  # m: a clearance equal to the radius is not free, however float32 rounds it


@dataclass(frozen=True, eq=False)
class _FieldGrid:
    """An occupancy grid in any dimension with its distance field: the queries both maps
    answer alike, indexed ``[i, j(, k)]``. Subclasses give ``occupied`` and ``distance``
    (metres to the nearest occupied cell's centre, float32)."""

    origin: FloatArray  # corner of cell (0, ...)
    resolution: float

    if TYPE_CHECKING:
        @property
        def occupied(self) -> BoolArray: ...

        @property
        def distance(self) -> NDArray[np.float32]: ...

    def cell_of(self, points: ArrayLike) -> IntArray:
        """``(N, D)`` indices of the cells holding ``points`` (possibly outside the grid)."""
        return _cell_of(points, self.origin, self.resolution)

    def center_of(self, cells: ArrayLike) -> FloatArray:
        return _center_of(cells, self.origin, self.resolution)

    def clearance(self, points: ArrayLike) -> FloatArray:
        """``(N,)`` distance field at each point's cell; 0 outside the grid."""
        return self._field.at(self.cell_of(points))

    @cached_property
    def _field(self) -> _Field | LayerField:
        return _Field(self.distance)

    def free(self, points: ArrayLike, radius: float) -> BoolArray:
        """``(N,)``: is each point's clearance more than ``radius``? (Equal is not.)"""
        return self.clearance(points) > radius + _TIE


@dataclass(frozen=True, eq=False)
class GridMap(_FieldGrid):
    """A 2-D occupancy grid (``(nx, ny)``) and its distance field."""

    occupied: BoolArray
    distance: NDArray[np.float32]

    @classmethod
    def from_occupancy(cls, occupied: BoolArray, origin: ArrayLike,
                       resolution: float) -> GridMap:
        occupied = np.array(occupied, dtype=bool)  # a copy: it is made read-only
        return cls(_frozen(np.array(origin, dtype=float)), resolution, _frozen(occupied),
                   _frozen(_edt(occupied, resolution)))


@dataclass(frozen=True, eq=False)
class VoxelMap(_FieldGrid):
    """A 3-D occupancy grid (``(nx, ny, nz)``) and its distance field; arrays are read-only
    and may be shared. Built from boxes, the map keeps the squared distance in cells
    (``squared``, 2 bytes a voxel), made a layer at a time as clearance queries reach it
    (``layers``); the whole of it, and the full occupancy and float32 distance arrays, are
    made only when asked for (they would take 5 bytes more a voxel, and most of a fresh
    process's time building the map)."""

    dense: tuple[BoolArray, NDArray[np.float32]] | None = None  # occupied, distance
    blocks: tuple[IntArray, IntArray] | None = None  # with layers: the boxes' cell ranges
    layers: Layers | None = None  # built from boxes: squared distances, a layer at a time

    @cached_property
    def squared(self) -> NDArray[np.unsignedinteger] | None:
        """``(nx, ny, nz)`` squared distances in cells (a view), every layer made."""
        return None if self.layers is None else _frozen(self.layers.whole())

    @cached_property
    def occupied(self) -> BoolArray:
        if self.dense is not None:
            return self.dense[0]
        assert self.squared is not None
        return _frozen(np.equal(self.squared, 0))

    @cached_property
    def distance(self) -> NDArray[np.float32]:
        if self.dense is not None:
            return self.dense[1]
        assert self.squared is not None
        return _frozen(_metres(self.squared, self.resolution))

    def occupied_cells(self, above: float) -> IntArray:
        """Indices of the occupied voxels whose centres lie higher than ``above``, in the
        order of ``np.argwhere(occupied)`` (only the layers above are looked at)."""
        nz = (self.layers.shape if self.layers is not None else self.occupied.shape)[2]
        layers = np.column_stack([np.zeros((nz, 2)), np.arange(nz)])
        higher = np.flatnonzero(self.center_of(layers)[:, 2] > above)
        if not len(higher):
            return np.zeros((0, 3), dtype=np.intp)
        k0 = int(higher[0])
        if self.blocks is None:
            cells: IntArray = np.argwhere(self.occupied[:, :, k0:])
            cells[:, 2] += k0
            return cells
        # the occupied voxels are those of the boxes' cell ranges: listed box by box, then
        # each once, in the order of np.argwhere
        assert self.layers is not None  # boxes' ranges come with the squared distances
        shape = self.layers.shape
        flat = []
        for first, stop in zip(*self.blocks, strict=True):
            first = np.maximum(first, (0, 0, k0))
            if np.all(stop > first):  # the box's cells' flat indices, as ravel_multi_index's
                x, y, z = (np.arange(a, b) for a, b in zip(first, stop, strict=True))
                flat.append(((x[:, None, None] * shape[1] + y[None, :, None]) * shape[2]
                             + z[None, None, :]).ravel())
        if not flat:
            return np.zeros((0, 3), dtype=np.intp)
        cells = np.sort(np.concatenate(flat))  # each once, in order: np.unique's values, by
        once = np.empty(len(cells), dtype=bool)  # a sort (its hash table is slower here)
        once[0] = True
        np.not_equal(cells[1:], cells[:-1], out=once[1:])
        return np.column_stack(np.unravel_index(cells[once], shape))

    @cached_property
    def _field(self) -> _Field | LayerField:
        if self.layers is None:
            return _Field(self.distance)
        resolution = self.resolution
        return LayerField(self.layers, partial(_metres, resolution=resolution))  # picklable

    def segment_free(self, p0: ArrayLike, p1: ArrayLike, radius: float) -> bool:
        """Is every point of the segment, sampled every half voxel, free for ``radius``?"""
        return self.path_free(np.array([p0, p1], dtype=float), radius)

    def path_free(self, points: ArrayLike, radius: float, step: float | None = None) -> bool:
        """Is every point of the polyline, sampled every ``step`` metres (by default half a
        voxel), free for ``radius``?"""
        dense = densify(points, step or self.resolution / 2)
        return bool(self.free(dense, radius).all())

    def slice_2d(self, z_lo: float, z_hi: float) -> GridMap:
        """Cells occupied by any voxel overlapping the heights ``z_lo`` to ``z_hi``."""
        nz = self.occupied.shape[2]
        k0 = math.floor((z_lo - self.origin[2]) / self.resolution + _EPS)
        k1 = math.ceil((z_hi - self.origin[2]) / self.resolution - _EPS)
        k0 = min(max(k0, 0), nz - 1)
        k1 = min(max(k1, k0 + 1), nz)
        occupied = np.asarray(self.occupied[:, :, k0:k1].any(axis=2))
        return GridMap.from_occupancy(occupied, self.origin[:2], self.resolution)


def densify(points: ArrayLike, step: float) -> FloatArray:
    """A polyline's vertices with points between them, consecutive points at most ``step`` apart."""
    p = np.asarray(points, dtype=float)
    if len(p) < 2:
        return p.copy()
    seg = p[1:] - p[:-1]
    count = np.maximum(np.ceil(np.linalg.norm(seg, axis=1) / step - 1e-9), 1).astype(np.int64)
    which = np.repeat(np.arange(len(seg)), count)
    t = (np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)) / count[which]
    return np.vstack([p[which] + t[:, None] * seg[which], p[-1:]])


def from_boxes(boxes: ArrayLike, lo: ArrayLike, hi: ArrayLike,
               resolution: float = 0.2) -> VoxelMap:
    """Rasterise ``(K, 2, 3)`` box corners over ``lo`` to ``hi``; beyond it counts as free."""
    lo_ = np.asarray(lo, dtype=float)
    span = (np.asarray(hi, dtype=float) - lo_) / resolution
    nx, ny, nz = (int(n) for n in np.maximum(np.ceil(span - _EPS), 1))
    corners = np.asarray(boxes, dtype=float).reshape(-1, 2, 3)
    first = np.floor((corners[:, 0] - lo_) / resolution + _EPS).astype(np.int64)
    stop = np.ceil((corners[:, 1] - lo_) / resolution - _EPS).astype(np.int64)
    first, stop = np.clip(first, 0, (nx, ny, nz)), np.clip(stop, 0, (nx, ny, nz))
    keep = np.all(stop > first, axis=1)
    if not keep.any():
        occupied = np.zeros((nx, ny, nz), dtype=bool)
        distance = np.full((nx, ny, nz), np.inf, dtype=np.float32)
        return VoxelMap(_frozen(lo_), resolution, dense=(_frozen(occupied), _frozen(distance)))
    # made layer-major (z, x, y) so each layer is contiguous; exposed as (x, y, z) views
    blocks = (_frozen(first[keep]), _frozen(stop[keep]))
    return VoxelMap(_frozen(lo_), resolution, blocks=blocks,
                    layers=Layers(blocks[0], blocks[1], (nx, ny, nz)))


def world_map(world: World, extra: ArrayLike | None = None, resolution: float | None = None,
              margin: float = 2.0) -> VoxelMap:
    """The world's solids, the ground and ``extra`` boxes over the site, up to ``margin`` above
    the tallest of them, at ``resolution`` (by default the world's: 0.2 m, or an imported
    world's voxel; doubled until the map has at most ``MAX_MAP_VOXELS``).

    Without ``extra`` the map depends on the world alone: it is built once per world and kept.
    """
    if resolution is None:
        resolution = world.map_resolution
    extra_boxes = np.zeros((0, 2, 3)) if extra is None else np.asarray(extra, dtype=float)
    if len(extra_boxes):
        return _build_world_map(world, extra_boxes.reshape(-1, 2, 3), resolution, margin)
    cache: dict[tuple[float, float], VoxelMap] = kept(world, "voxel_map", 16)
    key = (resolution, margin)
    if key not in cache:
        cache[key] = _build_world_map(world, extra_boxes, resolution, margin)
    return cache[key]


def _build_world_map(world: World, extra: FloatArray, resolution: float,
                     margin: float) -> VoxelMap:
    sx, sy = world.site
    ground = np.array([[[0.0, 0.0, -GROUND_DEPTH], [sx, sy, 0.0]]])
    boxes = np.concatenate([world.solid_array.reshape(-1, 2, 3), extra, ground])
    top = float(boxes[:, 1, 2].max()) + margin
    lo, hi = (0.0, 0.0, -GROUND_DEPTH), (sx, sy, top)
    if len(boxes) <= MANY_BOXES:
        return from_boxes(boxes, lo, hi, resolution)
    cells = math.prod(float(h - v) / resolution for v, h in zip(lo, hi, strict=True))
    while cells > MAX_MAP_VOXELS:  # the transform's memory grows with the cells
        resolution *= 2
        cells /= 8
        log.warning("world %s: the planner's map uses %g m voxels (finer would pass %s "
                    "voxels)", world.name, resolution, f"{MAX_MAP_VOXELS:,}")
    return from_boxes_rasterised(boxes, lo, hi, resolution)


def from_boxes_rasterised(boxes: ArrayLike, lo: ArrayLike, hi: ArrayLike,
                          resolution: float = 0.2) -> VoxelMap:
    """What :func:`from_boxes` gives, by stamping the boxes and one Euclidean distance
    transform: faster for thousands of boxes (an imported world's blocks), whose sweep
    :func:`from_boxes` does box by box."""
    lo_ = np.asarray(lo, dtype=float)
    span = (np.asarray(hi, dtype=float) - lo_) / resolution
    shape = tuple(int(n) for n in np.maximum(np.ceil(span - _EPS), 1))
    corners = np.asarray(boxes, dtype=float).reshape(-1, 2, 3)
    first = np.clip(np.floor((corners[:, 0] - lo_) / resolution + _EPS).astype(np.int64), 0,
                    shape)
    stop = np.clip(np.ceil((corners[:, 1] - lo_) / resolution - _EPS).astype(np.int64), 0,
                   shape)
    occupied = np.zeros(shape, dtype=bool)
    for (i0, j0, k0), (i1, j1, k1) in zip(first.tolist(), stop.tolist(), strict=True):
        occupied[i0:i1, j0:j1, k0:k1] = True
    return VoxelMap(_frozen(lo_), resolution,
                    dense=(_frozen(occupied), _frozen(_edt(occupied, resolution))))


def _edt(occupied: BoolArray, resolution: float) -> NDArray[np.float32]:
    if not occupied.any():
        return np.full(occupied.shape, np.inf, dtype=np.float32)
    distance = ndimage.distance_transform_edt(~occupied, sampling=resolution)
    return np.asarray(distance, dtype=np.float32)


def _cell_of(points: ArrayLike, origin: FloatArray, resolution: float) -> IntArray:
    p = np.asarray(points, dtype=float).reshape(-1, len(origin))
    return np.floor((p - origin) / resolution).astype(np.intp)


def _center_of(cells: ArrayLike, origin: FloatArray, resolution: float) -> FloatArray:
    c = np.asarray(cells, dtype=float).reshape(-1, len(origin))
    return origin + (c + 0.5) * resolution


def _metres(squared: NDArray[np.unsignedinteger], resolution: float) -> NDArray[np.float32]:
    """Squared distances in cells as float32 metres (``np.sqrt(a, dtype=...)`` takes 9 times
    as long on a map: cast, then the root in place)."""
    out = squared.astype(np.float32)
    np.sqrt(out, out=out)
    out *= np.float32(resolution)
    return out


class _Field:
    """Fast lookups in a field of any memory layout: one ``take`` on its flat memory, and
    ``convert`` on the values taken (as on the whole field: the same numbers)."""

    def __init__(self, field: NDArray[Any],
                 convert: Callable[[NDArray[Any]], NDArray[np.float32]] | None = None) -> None:
        self.convert = convert
        order = np.argsort(field.strides)[::-1]  # axes from the slowest-varying in memory
        dense = field.transpose(order)
        if not dense.flags.c_contiguous:
            dense = np.ascontiguousarray(dense)
        self.flat = dense.reshape(-1)
        steps = np.cumprod((1, *dense.shape[::-1]))[:-1][::-1]  # elements per step, dense axes
        self.steps = np.empty(field.ndim, dtype=np.intp)
        self.steps[order] = steps
        self.shape = np.array(field.shape)

    def at(self, cells: IntArray) -> FloatArray:
        """``(N,)`` values at ``cells``; 0 for cells outside the field."""
        inside = ((cells >= 0) & (cells < self.shape)).all(axis=1)
        taken = self.flat.take(np.where(inside, cells @ self.steps, 0))
        values = (taken if self.convert is None else self.convert(taken)).astype(float)
        values[~inside] = 0.0
        return values


def _frozen(array: A) -> A:
    array.setflags(write=False)
    return array
