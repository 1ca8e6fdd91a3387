"""A room's free floor from triangles: floor normals, wall tracing, boxes standing in it."""

from __future__ import annotations

import numpy as np
import pytest

from astralis_des.world import freespace
from astralis_des.world.freespace import (
    boxes_to_mesh,
    cell_centers,
    floor_mask,
    room_free_space,
    wall_trace,
)
from astralis_des.world.geometry import Box
from astralis_des.world.model import World

ROOM = "A.1.1.1"


def test_boxes_become_12_outward_triangles_each() -> None:
    """Two boxes give 16 vertices and 24 triangles whose normals point away from their box."""
    boxes = [Box((0, 0, 0), (1, 2, 3)), Box((5, 5, 5), (6, 6.5, 7))]
    vertices, faces = boxes_to_mesh(boxes)
    assert vertices.shape == (16, 3) and faces.shape == (24, 3)
    tri = vertices[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    centers = np.repeat([b.center for b in boxes], 12, axis=0)
    assert np.all((normal * (tri.mean(axis=1) - centers)).sum(axis=1) > 0)


def test_floor_mask_keeps_upward_faces_at_floor_height() -> None:
    """Only the slab's top counts: a shelf above and a box's underside at the floor do not."""
    slab = Box((0, 0, -0.2), (2, 1, 0))
    shelf = Box((0, 1.2, 0.5), (1, 1.8, 0.6))  # faces up, but 0.6 m above the floor
    hanging = Box((2.2, 0, 0.0), (2.8, 1, 0.4))  # its underside is at the floor, facing down
    vertices, faces = boxes_to_mesh([slab, shelf, hanging])
    mask = floor_mask(vertices, faces, (-0.5, -0.5), (3.5, 2.5), 0.0, 0.1)
    assert mask.shape == (40, 30)
    assert mask.sum() == 200  # the slab's 2 x 1 m top in 0.1 m cells
    centers = cell_centers((-0.5, -0.5), mask.shape, 0.1).reshape(40, 30, 2)
    on_slab = (centers[..., 0] > 0) & (centers[..., 0] < 2) & (centers[..., 1] > 0) & \
        (centers[..., 1] < 1)
    assert np.array_equal(mask & ~on_slab, np.zeros_like(mask)), "floor found off the slab"
    assert mask[on_slab].all()


def test_wall_trace_keeps_overlapping_boxes_solid() -> None:
    """Overlapping boxes occupy their union (nonzero winding), not the symmetric difference."""
    boxes = [Box((0.0, 0.0, 0.0), (1.0, 0.4, 2.0)), Box((0.6, 0.0, 0.0), (1.0, 1.0, 2.0))]
    vertices, faces = boxes_to_mesh(boxes)
    occupied, boundary = wall_trace(vertices, faces, (-0.5, -0.5), (1.5, 1.5), 0.1, 0.3)
    assert occupied.sum() == 10 * 4 + 4 * 6  # 1.0 x 0.4 plus 0.4 x 0.6 m, in 0.1 m cells
    assert not (occupied & boundary).any()
    assert boundary.sum() > 0


def test_empty_room_is_its_interior(world: World) -> None:
    """The free floor of an empty default room is its 3.8 x 6.8 m interior, within a cell."""
    space = room_free_space(world, ROOM)
    cols, rows = np.flatnonzero(space.free.any(axis=1)), np.flatnonzero(space.free.any(axis=0))
    assert len(cols) * space.cell == pytest.approx(3.8, abs=0.1)
    assert len(rows) * space.cell == pytest.approx(6.8, abs=0.1)
    assert space.area == pytest.approx(3.8 * 6.8, abs=0.1 * (3.8 + 6.8))
    room = world.rooms[ROOM]
    lo = np.array(room.box.lo[:2]) - 0.3
    vertices, faces = boxes_to_mesh([s.box for s in world.solids if s.kind == "slab"])
    floor = floor_mask(vertices, faces, lo, np.array(room.box.hi[:2]) + 0.3, 0.0, 0.1)
    assert floor[space.free].all()


def test_boundary_lies_along_the_walls(world: World) -> None:
    """Boundary cells touch a wall face; they ring the room except at the 1 m doorway."""
    space = room_free_space(world, ROOM)
    room = world.rooms[ROOM]
    centers = cell_centers(space.origin, space.shape, space.cell).reshape(*space.shape, 2)
    pts = centers[space.boundary]
    lo, hi = np.array(room.box.lo[:2]), np.array(room.box.hi[:2])
    to_wall = np.minimum(pts - lo, hi - pts).min(axis=1)
    assert to_wall.max() == pytest.approx(space.cell / 2)
    assert space.boundary.sum() == 2 * (38 + 68) - 4 - 10
    door_x = centers[space.door][:, 0]
    assert space.door.sum() == 10
    assert door_x.mean() == pytest.approx(room.door.center[0])
    assert not (space.door & space.boundary).any()


def test_a_box_in_the_room_removes_its_footprint(world: World) -> None:
    """A 1 x 0.5 m box standing in the room takes exactly its 0.5 m^2 off the free floor."""
    empty = room_free_space(world, ROOM)
    box = Box((65.0, 82.0, 0.0), (66.0, 82.5, 0.8))
    space = room_free_space(world, ROOM, extra=[box])
    assert empty.area - space.area == pytest.approx(0.5)
    assert not space.free[space.cells(box.lo, box.hi)].any()
    assert space.free[space.cells((64.9, 81.9), (66.1, 82.6))].sum() == 12 * 7 - 10 * 5


def test_a_low_box_does_not_block_the_slice(world: World) -> None:
    """A 0.2 m high box stays under the slice at 0.3 m and leaves the floor free."""
    low = Box((65.0, 82.0, 0.0), (66.0, 82.5, 0.2))
    assert room_free_space(world, ROOM, extra=[low]).area == room_free_space(world, ROOM).area


def test_upper_floor_room_uses_its_own_slab(world: World) -> None:
    """A second-floor room finds its floor at 3.5 m and the same interior area."""
    room_id = next(r for r in sorted(world.rooms) if world.rooms[r].floor == 2)
    space = room_free_space(world, room_id)
    assert space.floor_z == pytest.approx(3.5)
    assert space.area == pytest.approx(3.8 * 6.8)


def test_unknown_room_suggests_a_close_one(world: World) -> None:
    """An unknown room id is refused with a near match."""
    with pytest.raises(KeyError, match=r"unknown room 'A\.1\.1\.9'; did you mean 'A\.1\.1\.3'"):
        room_free_space(world, "A.1.1.9")


def test_grid_winding_counts_as_winding_does_on_every_point() -> None:
    """The grid's winding numbers, judged row by row, are the crossing rule's for each cell
    centre judged against every segment (as free space was traced before): random segments,
    and segments with their ends on cell centres and edges (the ties)."""
    rng = np.random.default_rng(7)
    for trial in range(200):
        nx, ny = (int(n) for n in rng.integers(1, 50, 2))
        lo = rng.uniform(-5.0, 5.0, 2).round(1)
        segments = rng.uniform(-6.0, 12.0, (int(rng.integers(0, 40)), 2, 2))
        if trial % 2:
            segments = np.round(segments * 20) / 20
        xs = lo[0] + (np.arange(nx) + 0.5) * 0.1
        ys = lo[1] + (np.arange(ny) + 0.5) * 0.1
        expected = _winding(freespace.cell_centers(lo, (nx, ny), 0.1), segments)
        assert np.array_equal(freespace.grid_winding(xs, ys, segments), expected), trial


def _winding(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Sunday's crossing rule, each point against every segment at once."""
    segments = segments[segments[:, 0, 1] != segments[:, 1, 1]]
    if len(segments) == 0:
        return np.zeros(len(points), dtype=np.int64)
    p, q = segments[None, :, 0], segments[None, :, 1]
    pt = points[:, None, :]
    side = (q[..., 0] - p[..., 0]) * (pt[..., 1] - p[..., 1]) - \
        (pt[..., 0] - p[..., 0]) * (q[..., 1] - p[..., 1])
    upward = (p[..., 1] <= pt[..., 1]) & (q[..., 1] > pt[..., 1]) & (side > 0)
    downward = (q[..., 1] <= pt[..., 1]) & (p[..., 1] > pt[..., 1]) & (side < 0)
    return np.asarray(upward.sum(axis=1) - downward.sum(axis=1), dtype=np.int64)
