"""Indoor analysis (issue 42) on realistic clouds: the 3-D lidar flown through buildings A and
B of the default world and through the irregular building (``tests/indoor_scan.py``), saved as
LAZ and PLY and read back; and both exported as meshes (building A as OBJ and GLB, the
irregular one as GLB), read back and sampled on their surfaces. Each: every true room
matched by a found room with an IoU of at least 0.8, every door found within 0.3 m of its
centre and 0.2 m of its width, no false room over 4 m²."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from indoor_scan import STEP, flight, lidar_scan, scene_mesh, write_cloud, write_mesh
from indoor_scenes import ROOT, Scene, building_a, irregular, score, world_building

from astralis_des.importers.indoor import Interior, find_interior, surface_points
from astralis_des.importers.las import read_las
from astralis_des.importers.mesh import choose_up, read_mesh, to_z_up
from astralis_des.importers.ply import read_ply
from astralis_des.importers.source import ReadRequest

MESH_SPACING = 0.07  # m between points on the mesh's surfaces: 1.25 million for building A


def _scanned(scene: Scene, path: Path, seed: int) -> tuple[Scene, Interior, np.ndarray]:
    """The scene's scan, written to ``path`` and read back by the importer's reader."""
    points = lidar_scan(scene, seed=seed)
    write_cloud(points, path)
    reader = read_ply if path.suffix == ".ply" else read_las
    cloud = reader(path, ReadRequest())
    read = cloud.coordinates(0, len(cloud))
    assert read.shape == points.shape and np.abs(read - points).max() <= 0.001
    return scene, find_interior(read), read


@pytest.fixture(scope="module")
def scan_a(tmp_path_factory: pytest.TempPathFactory) -> tuple[Scene, Interior, np.ndarray]:
    return _scanned(building_a(), tmp_path_factory.mktemp("scan") / "a.laz", seed=1)


@pytest.fixture(scope="module")
def scan_irregular(tmp_path_factory: pytest.TempPathFactory
                   ) -> tuple[Scene, Interior, np.ndarray]:
    return _scanned(irregular(), tmp_path_factory.mktemp("scan") / "irregular.ply", seed=2)


@pytest.fixture(scope="module", params=["a.obj", "a.glb", "irregular.glb"])
def mesh(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
         ) -> tuple[Scene, Interior]:
    scene = building_a() if request.param.startswith("a.") else irregular()
    path = write_mesh(scene, tmp_path_factory.mktemp("mesh") / request.param)
    mesh = read_mesh(path, ReadRequest())
    vertices = to_z_up(mesh.vertices, choose_up(mesh, "auto"))
    return scene, find_interior(surface_points(vertices, mesh.faces, MESH_SPACING, seed=3))


def _meets_the_goal(scene: Scene, interior: Interior) -> None:
    result = score(scene, interior)
    assert len(result.iou) == len(scene.rooms)
    assert min(result.iou.values()) >= 0.8, result.iou
    assert len(set(result.matched.values())) == len(scene.rooms)
    assert len(result.door_error) == len(scene.doors)
    assert all(c <= 0.3 and w <= 0.2 and same for c, w, same in result.door_error.values()), \
        result.door_error
    assert result.false_rooms == []


def test_the_flight_enters_every_room_through_its_door() -> None:
    """From the truth alone: stops in every room and space, 1.3 m over its floor, and in a
    doorway of every room and the first entrance; stops at most STEP apart up building
    A's stairwell, to its top storey."""
    for scene in (building_a(), irregular()):
        stops = flight(scene)
        flown = [d for d in scene.doors if np.any(
            (np.hypot(*(stops[:, :2] - d.centre).T) < 1e-6)
            & np.isclose(stops[:, 2], d.floor + 1.3))]
        assert next(d for d in scene.doors if d.entrance) in flown
        for room in scene.rooms + scene.spaces:
            x0, y0, x1, y1 = room.rects[0]
            inside = (stops[:, 0] > x0) & (stops[:, 0] < x1) & (stops[:, 1] > y0) & \
                (stops[:, 1] < y1) & np.isclose(stops[:, 2], room.floor + 1.3)
            assert inside.sum() >= 2, room.id
            if room in scene.rooms:
                assert any(d.floor == room.floor and _near(room.rects, d.centre)
                           for d in flown), room.id
    a = flight(building_a())
    climbing = ~np.isin(a[:, 2].round(3), [1.3, 4.8, 8.3])
    assert climbing.sum() >= 2  # between each two storeys
    for p in a[climbing]:  # each straight over a stop under it, at most STEP down
        under = np.all(np.isclose(a[:, :2], p[:2]), axis=1) & (a[:, 2] < p[2]) & \
            (a[:, 2] >= p[2] - STEP - 1e-9)
        assert under.any()
    assert a[-1, 2] == pytest.approx(8.3)


def _near(rects: tuple[tuple[float, float, float, float], ...], xy: tuple[float, float]
          ) -> bool:
    return any(r[0] - 0.3 <= xy[0] <= r[2] + 0.3 and r[1] - 0.3 <= xy[1] <= r[3] + 0.3
               for r in rects)


def test_lidar_scan_of_building_a(scan_a: tuple[Scene, Interior, np.ndarray]) -> None:
    """Three storeys at 0, 3.5 and 7 m; every room, door and the entrance found; no false
    room; the scan a couple of million points."""
    scene, interior, points = scan_a
    assert [round(s.z, 2) for s in interior.storeys] == [0.0, 3.5, 7.0]
    assert 1_000_000 < len(points) < 4_000_000
    _meets_the_goal(scene, interior)
    assert len(interior.entrances) == 1


def test_lidar_scan_of_building_b(tmp_path: Path) -> None:
    """The default world's other building: two storeys of three rooms off a corridor, its
    stairwell at the west end."""
    scene = world_building(ROOT / "worlds" / "urban_default.yaml", "B")
    scene, interior, _ = _scanned(scene, tmp_path / "b.laz", seed=4)
    assert [round(s.z, 2) for s in interior.storeys] == [0.0, 3.5]
    _meets_the_goal(scene, interior)


def test_lidar_scan_of_the_irregular_building(
        scan_irregular: tuple[Scene, Interior, np.ndarray]) -> None:
    """Storeys at 12 and 15 m; every room (L-shaped, behind a half-closed door, open plan
    with desks and a pillar), door and entrance; no false room, no door where there is
    none."""
    scene, interior, _ = scan_irregular
    assert [round(s.z, 2) for s in interior.storeys] == [12.0, 15.0]
    _meets_the_goal(scene, interior)
    assert score(scene, interior).extra_doors == 0
    assert len(interior.entrances) == 2


def test_buildings_as_meshes(mesh: tuple[Scene, Interior]) -> None:
    """Building A exported as OBJ and as GLB (Y-up), the irregular building as GLB, read back
    and sampled on every face, hidden ones too: the same rooms and doors; building A's
    sealed spaces at the corridor's east end (behind its last rooms, no door) are voids,
    not rooms."""
    scene, interior = mesh
    assert [round(s.z, 2) for s in interior.storeys] == scene.floors
    _meets_the_goal(scene, interior)
    if scene.name == "A":
        assert len(interior.voids) == 6
        assert all(v.kind == "void" and v.lo[0] > 76.0 for v in interior.voids)
    else:
        assert interior.voids == () and score(scene, interior).extra_doors == 0


def test_the_mesh_is_the_scenes_boxes() -> None:
    """Twelve outward triangles a box; its area is the boxes' surface."""
    scene = irregular(floors=(12.0,), furnished=False)
    mesh = scene_mesh(scene)
    boxes = np.array(scene.solids)
    size = boxes[:, 1] - boxes[:, 0]
    faces = 2 * (size[:, 0] * size[:, 1] + size[:, 1] * size[:, 2] + size[:, 0] * size[:, 2])
    assert len(mesh.faces) == 12 * len(boxes)
    assert mesh.area == pytest.approx(faces.sum())
    assert mesh.volume == pytest.approx(np.prod(size, axis=1).sum())


def test_surface_points_are_even_and_seeded() -> None:
    """About one point per spacing² on each face, on the face; the same seed, the same
    points."""
    vertices = np.array([[0, 0, 0], [4, 0, 0], [4, 2, 0], [0, 2, 0], [0, 0, 3]], dtype=float)
    faces = np.array([[0, 1, 2], [0, 2, 3], [0, 1, 4]])
    points = surface_points(vertices, faces, 0.1, seed=5)
    floor = points[:, 2] == 0.0
    assert floor.sum() == pytest.approx(800, abs=3)
    assert (~floor).sum() == pytest.approx(600, abs=3)
    assert np.all(points[~floor, 1] == 0.0)
    np.testing.assert_array_equal(points, surface_points(vertices, faces, 0.1, seed=5))
    with pytest.raises(ValueError, match="spacing must be positive"):
        surface_points(vertices, faces, 0.0)
