"""A room's free floor, found from triangles in two stages (the paper's obstacle placement).

1. Floor normals: triangles facing up at the room's floor height are rasterised into a grid.
2. Wall tracing: a horizontal slice just above the floor marks what stands on it (the nonzero
   winding rule over the slice's segments, so overlapping closed meshes stay solid), and the
   free cells touching it are the traced boundary, where furniture goes with its back to a wall.

Both stages see only vertices and faces, so an imported mesh works as well as the built boxes.
Grids are indexed ``[i, j]``: cell ``(i, j)`` is centred at ``origin + (i + .5, j + .5) * cell``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from astralis_des.errors import suggest
from astralis_des.memo import kept
from astralis_des.world.geometry import Box, FloatArray, boxes_array, inside_polygon
from astralis_des.world.model import BLOCK, World

BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.int64]
XY = Sequence[float] | FloatArray  # a point or corner; only x and y are read

UP = 0.9  # n_z of a floor triangle's unit normal
FLOOR_TOLERANCE = 0.05  # m: a floor triangle lies this close to the floor's height
SLICE_HEIGHT = 0.3  # m above the floor: what crosses it stands on the floor
MARGIN = 0.3  # m of grid around the room: its walls and the doorway's far side
_CHUNK = 256  # triangles tested against every cell at once

# Corner k of a box is (lo or hi) per bit of k: x = bit 0, y = bit 1, z = bit 2.
_CORNERS = np.array([[k & 1, (k >> 1) & 1, (k >> 2) & 1] for k in range(8)], dtype=float)
_FACES = np.array([
    (0, 2, 1), (1, 2, 3),  # z = lo, facing down
    (4, 5, 6), (5, 7, 6),  # z = hi, facing up
    (0, 1, 5), (0, 5, 4),  # y = lo
    (2, 7, 3), (2, 6, 7),  # y = hi
    (0, 4, 6), (0, 6, 2),  # x = lo
    (1, 3, 7), (1, 7, 5),  # x = hi
])
CROSS = ndimage.generate_binary_structure(2, 1)


def boxes_to_mesh(boxes: Sequence[Box]) -> tuple[FloatArray, IntArray]:
    """``(8K, 3)`` vertices and ``(12K, 3)`` faces of ``K`` boxes, normals pointing out."""
    if not boxes:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    corners = boxes_array(list(boxes))
    lo, size = corners[:, 0], corners[:, 1] - corners[:, 0]
    vertices = lo[:, None, :] + _CORNERS[None] * size[:, None, :]
    faces = _FACES[None] + 8 * np.arange(len(corners))[:, None, None]
    return vertices.reshape(-1, 3), faces.reshape(-1, 3).astype(np.int64)


def grid_shape(bounds_lo: XY, bounds_hi: XY,
               cell: float) -> tuple[int, int]:
    n = np.ceil((np.asarray(bounds_hi[:2]) - np.asarray(bounds_lo[:2])) / cell - 1e-6)
    return int(max(n[0], 0)), int(max(n[1], 0))


def cell_centers(bounds_lo: XY, shape: tuple[int, int], cell: float) -> FloatArray:
    """``(nx * ny, 2)`` cell centres in ``[i, j]`` row-major order."""
    xs = bounds_lo[0] + (np.arange(shape[0]) + 0.5) * cell
    ys = bounds_lo[1] + (np.arange(shape[1]) + 0.5) * cell
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel()])


def floor_mask(vertices: FloatArray, faces: IntArray, bounds_lo: XY,
               bounds_hi: XY, floor_z: float, cell: float) -> BoolArray:
    """Cells whose centre lies on an upward triangle at ``floor_z`` (stage 1: floor normals)."""
    shape = grid_shape(bounds_lo, bounds_hi, cell)
    tri = np.asarray(vertices, dtype=float)[np.asarray(faces, dtype=np.int64)]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    up = normal[:, 2] > UP * np.where(length > 0, length, np.inf)
    level = np.all(np.abs(tri[:, :, 2] - floor_z) <= FLOOR_TOLERANCE, axis=1)
    tri = _in_bounds(tri[up & level][:, :, :2], bounds_lo, bounds_hi)
    points = cell_centers(bounds_lo, shape, cell)
    hit = np.zeros(len(points), dtype=bool)
    for start in range(0, len(tri), _CHUNK):
        hit |= _points_in_triangles(points, tri[start:start + _CHUNK])
    return hit.reshape(shape)


def _in_bounds(tri: FloatArray, lo: XY, hi: XY) -> FloatArray:
    """Triangles (or segments) whose x, y extent meets the grid's."""
    keep = np.all((tri.min(axis=1) <= np.asarray(hi[:2])) &
                  (tri.max(axis=1) >= np.asarray(lo[:2])), axis=1)
    return tri[keep]


def _points_in_triangles(points: FloatArray, tri: FloatArray) -> BoolArray:
    """``(N,)``: is each point inside (or on) any of the ``(T, 3, 2)`` triangles?"""
    if len(tri) == 0:
        return np.zeros(len(points), dtype=bool)
    a = tri[None, :, 0]
    v0, v1 = tri[None, :, 1] - a, tri[None, :, 2] - a
    v2 = points[:, None, :] - a
    d00, d01, d11 = (v0 * v0).sum(-1), (v0 * v1).sum(-1), (v1 * v1).sum(-1)
    d20, d21 = (v2 * v0).sum(-1), (v2 * v1).sum(-1)
    denom = d00 * d11 - d01 * d01
    eps = 1e-9
    with np.errstate(divide="ignore", invalid="ignore"):  # a triangle of no area: denom 0
        v = (d11 * d20 - d01 * d21) / denom
        w = (d00 * d21 - d01 * d20) / denom
        inside = (denom > 0) & (v >= -eps) & (w >= -eps) & (v + w <= 1 + eps)
    return np.asarray(inside.any(axis=1))


def slice_segments(vertices: FloatArray, faces: IntArray, z: float) -> FloatArray:
    """``(S, 2, 2)`` segments where the plane ``z`` cuts the triangles, outward side on the right.

    A vertex exactly at ``z`` counts as below, so a face touching the plane cuts nothing.
    """
    tri = np.asarray(vertices, dtype=float)[np.asarray(faces, dtype=np.int64)]
    above = tri[:, :, 2] > z
    crossing = (above.sum(axis=1) % 3) != 0
    tri, above = tri[crossing], above[crossing]
    if len(tri) == 0:
        return np.zeros((0, 2, 2))
    ends = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        za, zb = tri[:, a, 2], tri[:, b, 2]
        cut = above[:, a] != above[:, b]
        t = np.where(cut, (z - za) / np.where(cut, zb - za, 1.0), 0.0)
        point = tri[:, a, :2] + t[:, None] * (tri[:, b, :2] - tri[:, a, :2])
        ends.append((cut, point))
    # Exactly two edges of a crossing triangle are cut: the first cut one and the last.
    cuts = np.stack([c for c, _ in ends], axis=1)
    points = np.stack([p for _, p in ends], axis=1)
    first, last = cuts.argmax(axis=1), 2 - cuts[:, ::-1].argmax(axis=1)
    rows = np.arange(len(tri))
    p, q = points[rows, first], points[rows, last]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, :2]
    forward = np.column_stack([-normal[:, 1], normal[:, 0]])  # the normal turned left
    flip = ((q - p) * forward).sum(axis=1) < 0
    p, q = np.where(flip[:, None], q, p), np.where(flip[:, None], p, q)
    return np.stack([p, q], axis=1)


def grid_winding(xs: np.ndarray, ys: np.ndarray, segments: FloatArray) -> IntArray:
    """Winding number of each grid point ``(xs[i], ys[j])`` about the oriented segments
    (Sunday's crossing rule), in ``[i, j]`` order. A segment counts only for the rows of
    points its y span takes in (the rule's first test), so each row is judged against the
    few segments that cross it rather than against all of them; a level segment never
    crosses a ray towards +x and counts for no point."""
    segments = segments[segments[:, 0, 1] != segments[:, 1, 1]]
    wind = np.zeros((len(xs), len(ys)), dtype=np.int64)
    if len(segments) == 0 or len(xs) == 0:
        return wind.ravel()
    p, q = segments[:, 0], segments[:, 1]
    y = ys[:, None]
    upward = (p[None, :, 1] <= y) & (q[None, :, 1] > y)
    downward = (q[None, :, 1] <= y) & (p[None, :, 1] > y)
    row, seg = np.nonzero(upward | downward)  # (row of points, segment) pairs that cross
    if len(row) == 0:
        return wind.ravel()
    p, q, at = p[seg][:, None, :], q[seg][:, None, :], ys[row][:, None]
    side = (q[..., 0] - p[..., 0]) * (at - p[..., 1]) - \
        (xs[None, :] - p[..., 0]) * (q[..., 1] - p[..., 1])
    counts = np.where(upward[row, seg][:, None], side > 0, 0).astype(np.int64) - \
        np.where(downward[row, seg][:, None], side < 0, 0).astype(np.int64)
    np.add.at(wind.T, row, counts)
    return wind.ravel()


def segment_cells(segments: FloatArray, bounds_lo: XY, shape: tuple[int, int],
                  cell: float) -> BoolArray:
    """Cells the segments pass through, so thin or open surfaces block too.

    Points every quarter cell are binned; a point on a cell edge marks neither side, so a
    closed mesh's face lying along a grid line does not spill into the free cell beside it.
    """
    mask = np.zeros(shape, dtype=bool)
    if len(segments) == 0:
        return mask
    p, d = segments[:, 0], segments[:, 1] - segments[:, 0]
    steps = np.maximum(np.ceil(np.linalg.norm(d, axis=1) / (cell / 4)), 1).astype(np.int64)
    which = np.repeat(np.arange(len(segments)), steps + 1)
    start = np.repeat(np.cumsum(steps + 1) - (steps + 1), steps + 1)
    t = (np.arange(len(which)) - start) / steps[which]
    u = (p[which] + t[:, None] * d[which] - np.asarray(bounds_lo[:2])) / cell
    low, high = np.floor(u + 1e-6), np.floor(u - 1e-6)
    keep = np.all((low == high) & (low >= 0) & (low < np.asarray(shape)), axis=1)
    index = low[keep].astype(np.int64)
    mask[index[:, 0], index[:, 1]] = True
    return mask


def wall_trace(vertices: FloatArray, faces: IntArray, bounds_lo: XY,
               bounds_hi: XY, cell: float, slice_z: float,
               floor: BoolArray | None = None) -> tuple[BoolArray, BoolArray]:
    """Stage 2: cells occupied at height ``slice_z``, and the boundary of the free cells.

    The boundary is the free cells (on ``floor``, if given, and unoccupied) with a 4-neighbour
    that is occupied, has no floor or lies outside the grid.
    """
    shape = grid_shape(bounds_lo, bounds_hi, cell)
    segments = slice_segments(vertices, faces, slice_z)
    lo, hi = np.asarray(bounds_lo[:2]) - cell, np.asarray(bounds_hi[:2]) + cell
    # The winding rule counts crossings of a ray towards +x: keep what lies on such a ray.
    on_rays = (segments[:, :, 1].max(axis=1) >= lo[1]) & \
        (segments[:, :, 1].min(axis=1) <= hi[1]) & (segments[:, :, 0].max(axis=1) >= lo[0])
    xs = bounds_lo[0] + (np.arange(shape[0]) + 0.5) * cell  # the cells' centres
    ys = bounds_lo[1] + (np.arange(shape[1]) + 0.5) * cell  # (as cell_centers makes them)
    occupied = (grid_winding(xs, ys, segments[on_rays]) != 0).reshape(shape)
    occupied |= segment_cells(_in_bounds(segments, lo, hi), bounds_lo, shape, cell)
    free = ~occupied if floor is None else floor & ~occupied
    blocked = np.pad(~free, 1, constant_values=True)
    boundary = free & ndimage.binary_dilation(blocked, CROSS)[1:-1, 1:-1]
    return occupied, boundary


@dataclass(frozen=True, eq=False)
class FreeSpace:
    """The free floor of one room on a grid reaching ``MARGIN`` beyond its walls."""

    room: str
    origin: tuple[float, float]
    cell: float
    floor_z: float
    free: BoolArray  # floor, unoccupied, inside the room, connected to its centre
    boundary: BoolArray  # free cells along a wall (the traced boundary)
    open_floor: BoolArray  # floor and unoccupied anywhere on the grid (doorway, corridor)
    inside: BoolArray  # cells whose centre is inside the room's box (and outline)
    door: BoolArray  # free cells opening onto the doorway

    @property
    def area(self) -> float:
        return float(self.free.sum()) * self.cell ** 2

    @property
    def shape(self) -> tuple[int, int]:
        return (int(self.free.shape[0]), int(self.free.shape[1]))

    def cells(self, lo: XY, hi: XY) -> tuple[slice, slice]:
        """Cells a rectangle overlaps (touching an edge is not overlapping), clipped to the grid."""
        out = []
        for k in (0, 1):
            first = math.floor((lo[k] - self.origin[k]) / self.cell + 1e-6)
            last = math.ceil((hi[k] - self.origin[k]) / self.cell - 1e-6)
            size = self.free.shape[k]
            out.append(slice(min(max(first, 0), size), min(max(last, 0), size)))
        return out[0], out[1]

    def wall_sides(self) -> BoolArray:
        """``(4, nx, ny)``: free cells whose neighbour towards -x, +x, -y, +y is blocked."""
        blocked = np.pad(~self.open_floor, 1, constant_values=True)
        return np.stack([
            self.boundary & blocked[:-2, 1:-1], self.boundary & blocked[2:, 1:-1],
            self.boundary & blocked[1:-1, :-2], self.boundary & blocked[1:-1, 2:],
        ])


def room_free_space(world: World, room_id: str, extra: Sequence[Box] = (),
                    cell: float = 0.1) -> FreeSpace:
    """The free floor of a room, from the world's solids around it and ``extra`` boxes.

    Without ``extra`` the answer depends on the world alone: it is computed once per world
    and room (every mission furnishing that room starts from it) and kept read-only.
    """
    if room_id not in world.rooms:
        raise KeyError(f"unknown room {room_id!r}; {suggest(room_id, world.rooms)}")
    if extra:
        return _room_free_space(world, room_id, extra, cell)
    cache: dict[tuple[str, float], FreeSpace] = kept(world, "free_space", 100_000)
    key = (room_id, cell)
    if key not in cache:
        space = _room_free_space(world, room_id, (), cell)
        for grid in (space.free, space.boundary, space.open_floor, space.inside, space.door):
            grid.setflags(write=False)
        cache[key] = space
    return cache[key]


def _room_free_space(world: World, room_id: str, extra: Sequence[Box],
                     cell: float) -> FreeSpace:
    room = world.rooms[room_id]
    floor_z = room.box.lo[2]
    margin = cell * np.ceil(MARGIN / cell - 1e-9)
    lo = np.array(room.box.lo[:2]) - margin
    hi = np.array(room.box.hi[:2]) + margin
    near = _solids_near(world, lo, hi, floor_z)
    vertices, faces = _with_mesh(world, *boxes_to_mesh(near + list(extra)), lo, hi, floor_z)
    floor = floor_mask(vertices, faces, lo, hi, floor_z, cell)
    occupied, boundary = wall_trace(vertices, faces, lo, hi, cell, floor_z + SLICE_HEIGHT, floor)
    open_floor = floor & ~occupied
    shape = floor.shape
    centers = cell_centers(lo, shape, cell)
    inside = np.all((centers >= np.array(room.box.lo[:2])) &
                    (centers <= np.array(room.box.hi[:2])), axis=1).reshape(shape)
    if room.outline:  # a room that is no rectangle: its outline, not its bounds
        inside &= inside_polygon(centers, room.outline).reshape(shape)
    free = _component_at(open_floor & inside, centers, room.center[:2])
    beyond = open_floor & ~inside
    door = free & ndimage.binary_dilation(beyond, CROSS)
    return FreeSpace(room_id, (float(lo[0]), float(lo[1])), cell, floor_z, free,
                     boundary & free, open_floor, inside, door)


def _solids_near(world: World, lo: FloatArray, hi: FloatArray, floor_z: float) -> list[Box]:
    """Solids reaching into the grid between just below the floor and above the slice; not an
    imported mesh's voxel blocks, whose triangles are used instead."""
    boxes = world.solid_array
    if len(boxes) == 0:
        return []
    z_lo, z_hi = floor_z - FLOOR_TOLERANCE, floor_z + SLICE_HEIGHT + FLOOR_TOLERANCE
    near = np.all((boxes[:, 0, :2] <= hi) & (boxes[:, 1, :2] >= lo), axis=1) & \
        (boxes[:, 0, 2] <= z_hi) & (boxes[:, 1, 2] >= z_lo)
    has_mesh = world.imported is not None and world.imported.vertices is not None
    return [world.solids[k].box for k in np.flatnonzero(near)
            if not (has_mesh and world.solids[k].kind == BLOCK)]


def _with_mesh(world: World, vertices: FloatArray, faces: IntArray, lo: FloatArray,
               hi: FloatArray, floor_z: float) -> tuple[FloatArray, IntArray]:
    """The boxes' triangles and, in an imported mesh world, the mesh's triangles near the
    grid: floors and walls as they were modelled."""
    if world.imported is None or world.imported.vertices is None:
        return vertices, faces
    z_lo, z_hi = floor_z - FLOOR_TOLERANCE, floor_z + SLICE_HEIGHT + FLOOR_TOLERANCE
    more, tri = world.imported.triangles_near(np.array([*lo[:2], z_lo]),
                                              np.array([*hi[:2], z_hi]))
    return np.vstack([vertices, more]), np.vstack([faces, tri + len(vertices)])


def _component_at(mask: BoolArray, centers: FloatArray, point: XY) -> BoolArray:
    """The 4-connected part of ``mask`` holding its cell nearest to ``point``."""
    if not mask.any():
        return mask.copy()
    labels, _ = ndimage.label(mask, CROSS)
    flat = np.flatnonzero(mask.ravel())
    nearest = flat[np.argmin(((centers[flat] - np.asarray(point[:2])) ** 2).sum(axis=1))]
    return np.asarray(labels == labels.ravel()[nearest])
