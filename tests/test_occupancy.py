"""The world's occupancy: voxels, their distance field, floor slices and clearance queries."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from astralis_des.planning.occupancy import VoxelMap, densify, from_boxes, world_map
from astralis_des.world.model import World

RES = 0.2


@pytest.fixture(scope="module")
def vmap(world: World) -> VoxelMap:
    return world_map(world)


def box_distance(point: np.ndarray, boxes: np.ndarray) -> float:
    """Euclidean distance from a point to the nearest of ``(K, 2, 3)`` boxes."""
    gap = np.maximum(np.maximum(boxes[:, 0] - point, point - boxes[:, 1]), 0.0)
    return float(np.linalg.norm(gap, axis=1).min())


def test_a_thin_wall_is_occupied_and_its_neighbours_one_voxel_away() -> None:
    """A 0.1 m wall fills its voxel column; the voxels either side are at one resolution."""
    m = from_boxes(np.array([[[1.05, 0.0, 0.0], [1.15, 2.0, 2.0]]]), (0, 0, 0), (3, 2, 2), RES)
    assert m.occupied.shape == (15, 10, 10)
    assert m.occupied[5].all() and m.occupied.sum() == 100
    assert np.allclose(m.distance[4], RES) and np.allclose(m.distance[6], RES)
    assert np.allclose(m.distance[8], 3 * RES)
    assert not m.free([[1.1, 1.0, 1.0]], 0.0)[0]
    beside = [[0.9, 1.0, 1.0]]  # one voxel from the wall: clear by 0.2 m, not by more
    assert m.free(beside, 0.19)[0] and not m.free(beside, RES)[0]


def test_a_box_touching_a_voxel_face_does_not_occupy_it() -> None:
    """A wall from 1.0 to 1.2 m occupies one voxel layer, from 1.1 to 1.3 m two."""
    aligned = from_boxes(np.array([[[1.0, 0, 0], [1.2, 2, 2]]]), (0, 0, 0), (3, 2, 2), RES)
    straddling = from_boxes(np.array([[[1.1, 0, 0], [1.3, 2, 2]]]), (0, 0, 0), (3, 2, 2), RES)
    assert np.flatnonzero(aligned.occupied[:, 0, 0]).tolist() == [5]
    assert np.flatnonzero(straddling.occupied[:, 0, 0]).tolist() == [5, 6]


def test_the_distance_field_is_scipys_euclidean_transform() -> None:
    """Random boxes, with and without a ground box under all of them: the same as scipy."""
    rng = np.random.default_rng(7)
    for trial in range(6):
        corner = rng.uniform(0, 4, (4, 3))
        boxes = np.stack([corner, corner + rng.uniform(0.05, 1.5, (4, 3))], axis=1)
        if trial % 2:
            boxes = np.concatenate([boxes, [[[-1, -1, -1], [6, 6, 0.3]]]])
        m = from_boxes(boxes, (0, 0, 0), (5, 4, 3), RES)
        expected = ndimage.distance_transform_edt(~m.occupied, sampling=RES)
        assert np.allclose(m.distance, expected, atol=1e-5)


def test_clearance_at_a_room_centre_is_the_distance_to_its_nearest_surface(
        world: World, vmap: VoxelMap) -> None:
    """Mid-height in room A.2.1.2 the map's clearance is the nearest wall or slab's distance."""
    point = np.array(world.rooms["A.2.1.2"].box.center)
    expected = box_distance(point, world.solid_array)
    assert expected == pytest.approx(1.65, abs=0.01)
    assert vmap.clearance(point)[0] == pytest.approx(expected, abs=RES)


def test_a_door_is_free_for_a_small_body_and_its_wall_is_not(
        world: World, vmap: VoxelMap) -> None:
    """At 1 m above the floor, the middle of a 1 m door is clear by 0.3 m; the wall beside not."""
    x, y, z = world.rooms["A.1.1.1"].door.center
    assert vmap.free([[x, y, z + 1.0]], 0.3)[0]
    assert not vmap.free([[x + 1.0, y, z + 1.0]], 0.0)[0]
    assert vmap.segment_free([x, y - 1.0, z + 1.0], [x, y + 1.0, z + 1.0], 0.3)
    assert not vmap.segment_free([x + 1.0, y - 1.0, z + 1.0], [x + 1.0, y + 1.0, z + 1.0], 0.0)


def test_the_ground_floor_slice_shows_the_corridor_free(world: World, vmap: VoxelMap) -> None:
    """Along the ground-floor corridor's centre line every cell is clear by 0.35 m."""
    corridor = world.spaces["A.1.corridor"].box
    grid = vmap.slice_2d(0.3, 1.2)
    y = (corridor.lo[1] + corridor.hi[1]) / 2
    line = np.column_stack([np.linspace(corridor.lo[0] + 0.5, corridor.hi[0] - 0.5, 200),
                            np.full(200, y)])
    assert grid.free(line, 0.35).all()
    wall = np.array([[corridor.lo[0] + 1.0, corridor.lo[1] - 0.05]])  # beside a door
    assert grid.occupied[tuple(grid.cell_of(wall)[0])]
    assert np.allclose(grid.center_of(grid.cell_of(line[:1])), line[:1], atol=RES / 2)


def test_furniture_boxes_are_occupied_in_a_map_of_their_own(
        world: World, vmap: VoxelMap) -> None:
    """A table in room A.1.1.1 is occupied in a map with it; the shared map stays as it was."""
    cx, cy, _ = world.rooms["A.1.1.1"].box.center
    table = np.array([[[cx - 0.6, cy - 0.4, 0.0], [cx + 0.6, cy + 0.4, 0.75]]])
    furnished = world_map(world, extra=table)
    point = [[cx, cy, 0.5]]
    assert furnished.clearance(point)[0] == 0.0
    assert vmap.clearance(point)[0] == pytest.approx(0.5, abs=RES)
    assert furnished is not vmap and world_map(world) is vmap


def test_points_outside_the_map_have_no_clearance(vmap: VoxelMap) -> None:
    """Beyond the site or above the map, clearance is 0 and nothing is free."""
    outside = np.array([[-5.0, 10.0, 1.0], [10.0, 500.0, 1.0], [10.0, 10.0, 100.0]])
    assert vmap.clearance(outside).tolist() == [0.0, 0.0, 0.0]
    assert not vmap.free(outside, 0.0).any()
    assert vmap.clearance([10.0, 10.0, 1.5])[0] == pytest.approx(1.5, abs=RES)


def test_the_map_of_a_world_is_built_once(world: World, vmap: VoxelMap) -> None:
    """Asking twice gives the same read-only object, as tall as the tallest solid + 2 m."""
    assert world_map(world) is vmap
    assert not vmap.distance.flags.writeable and not vmap.occupied.flags.writeable
    top = vmap.origin[2] + vmap.occupied.shape[2] * RES
    assert top == pytest.approx(world.solid_array[:, 1, 2].max() + 2.0, abs=RES)


def test_densify_keeps_vertices_and_bounds_the_spacing() -> None:
    """Points at most a step apart, the polyline's vertices among them."""
    points = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0, 0.25, 0]])
    dense = densify(points, 0.3)
    assert np.linalg.norm(np.diff(dense, axis=0), axis=1).max() <= 0.3
    assert all(any(np.allclose(v, d) for d in dense) for v in points)


def test_clearance_and_occupied_cells_read_the_squared_distances_as_the_full_field() -> None:
    """A map built from boxes answers clearance from its squared distances and lists the
    occupied voxels above a height layer by layer: the same numbers, in the same order, as
    the full float32 field and ``np.argwhere`` over the whole occupancy."""
    rng = np.random.default_rng(5)
    lo = rng.uniform(0, 4, (12, 3))
    boxes = np.stack([lo, lo + rng.uniform(0.1, 1.5, (12, 3))], axis=1)
    m = from_boxes(boxes, (0, 0, -0.4), (6, 6, 6), RES)
    assert m.squared is not None
    points = rng.uniform(-0.5, 6.5, (2000, 3))
    cells = m.cell_of(points)
    inside = ((cells >= 0) & (cells < m.distance.shape)).all(axis=1)
    expected = np.zeros(len(points))
    expected[inside] = m.distance[tuple(cells[inside].T)]
    assert np.array_equal(m.clearance(points), expected)
    centres = m.center_of(np.argwhere(m.occupied))
    above = m.center_of(m.occupied_cells(above=1.0))
    assert len(above) and np.array_equal(above, centres[centres[:, 2] > 1.0])
