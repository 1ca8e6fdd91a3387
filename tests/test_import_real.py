"""Real data: the Autzen aerial LiDAR (data/real/autzen_trim.laz), and the Stanford
bunny and the samurai monastery meshes of pybullet_data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet_data
import pytest

from astralis_des.importers import ImportOptions, import_world
from astralis_des.importers.ground import find_ground
from astralis_des.importers.las import read_las
from astralis_des.importers.source import ReadRequest
from astralis_des.world.build import load_world
from astralis_des.world.clutter import place_room

ROOT = Path(__file__).resolve().parents[1]
AUTZEN = ROOT / "data" / "real" / "autzen_trim.laz"
MESHES = Path(pybullet_data.getDataPath())


@pytest.fixture(scope="module")
def autzen() -> Path:
    assert AUTZEN.is_file(), f"{AUTZEN} is part of the repository (data/real/README.md)"
    return AUTZEN


def test_autzen_imports_in_metres_from_its_feet(autzen: Path, tmp_path: Path) -> None:
    """110,000 points in feet (the header's GeoTIFF keys: EPSG 9002) become a 363 m x 176 m
    site of 1 m voxels (its points are 0.6 m apart); the ground is the file's class 2 (23.7% of
    the points); trees stand up to 33 m (34 voxels; 33.2 m at 0.2 m)."""
    report = import_world(autzen, tmp_path / "autzen.yaml")
    assert report.points == 110_000 and report.dropped == 0
    assert report.scale == pytest.approx(0.3048) and "EPSG 9002" in report.units
    assert report.voxel == 1.0 and report.site == pytest.approx((363.0, 176.0))
    assert "voxel 1 m, the finest no finer than the points (one point per 0.596 m: 110,000 " \
        "points over the 39,116 m^2 they cover); --voxel to choose" in report.notes
    assert report.ground == "classification"
    assert report.ground_share == pytest.approx(0.2373, abs=1e-4)
    world = load_world((tmp_path / "autzen.yaml").resolve())
    assert world.block_array[:, 1, 2].max() == 34.0
    fine = import_world(autzen, tmp_path / "fine.yaml", ImportOptions(voxel=0.2))
    assert fine.site == pytest.approx((363.0, 175.6))
    tops = load_world((tmp_path / "fine.yaml").resolve()).block_array[:, 1, 2]
    assert tops.max() == pytest.approx(33.2, abs=0.2)
    assert world.imported is not None and world.imported.cloud is not None
    assert len(world.imported.cloud) == 50_000


def test_autzen_ground_estimate_agrees_with_its_classification(autzen: Path) -> None:
    """Without the classes, the grid estimate's ground share is within 5 points of the
    classification's, four points in five get the same label, and its surface lies within
    5 cm (median) of the classified ground points."""
    cloud = read_las(autzen, ReadRequest())
    assert cloud.classification is not None
    points = cloud.coordinates(0, len(cloud)) * 0.3048
    classified = cloud.classification == 2
    ground = find_ground(points, None, "grid", np.random.default_rng(0))
    mask = ground.is_ground(points, None)
    assert mask.mean() == pytest.approx(classified.mean(), abs=0.05)
    assert float(np.mean(mask == classified)) > 0.78
    error = np.abs(points[classified, 2] - ground.height(points[classified]))
    assert float(np.median(error)) < 0.05


def test_committed_autzen_world_is_what_the_readme_command_makes(autzen: Path,
                                                                  tmp_path: Path) -> None:
    """worlds/autzen.yaml holds the blocks and areas that re-importing the file gives."""
    import_world(autzen, tmp_path / "autzen.yaml", ImportOptions(voxel=1.0))
    fresh = load_world((tmp_path / "autzen.yaml").resolve())
    committed = load_world(ROOT / "worlds" / "autzen.yaml")
    assert np.array_equal(fresh.block_array, committed.block_array)
    assert [(a.id, a.box) for a in fresh.areas] == [(a.id, a.box) for a in committed.areas]


@pytest.mark.parametrize("collision", ["concave", "convex"])
def test_bunny_is_a_solid_statue_in_physics(tmp_path: Path, collision: str) -> None:
    """The closed bunny is solid inside (blocks fill it); PyBullet stands it up, as a static
    concave mesh or as V-HACD's convex parts, and a ray from above lands on its back."""
    from astralis_des.physics.client import PhysicsClient

    report = import_world(MESHES / "bunny.obj", tmp_path / "bunny.yaml",
                          ImportOptions(margin=10.0, area_size=8.0, collision=collision))
    world = load_world((tmp_path / "bunny.yaml").resolve())
    assert report.extra["watertight"] and len(report.areas) == 4
    middle = world.imported.vertices.mean(axis=0)  # type: ignore[union-attr]
    assert np.all((middle >= world.block_array[:, 0]) &
                  (middle <= world.block_array[:, 1]), axis=1).any()
    client = PhysicsClient(world, 1 / 240, 1, 10)
    try:
        hit = client.call("rayTest", [middle[0], middle[1], 5.0], [middle[0], middle[1], -1.0])[0]
        assert hit[0] not in (-1, client.ground)
        assert 0.5 < hit[3][2] < 2.0
    finally:
        client.close()


def test_monastery_floors_take_furniture_from_their_normals(tmp_path: Path) -> None:
    """The monastery (Y-up OBJ) stands up; its floors are found from upward triangles; areas
    lie on its main floor, and furnishing one puts every item on that floor."""
    report = import_world(MESHES / "samurai_monastry.obj", tmp_path / "monastery.yaml",
                          ImportOptions(voxel=0.5, area_size=10.0))
    world = load_world((tmp_path / "monastery.yaml").resolve())
    assert world.imported is not None and world.imported.source["up"] == "y"
    assert report.kind == "mesh" and report.points == 124_789  # triangles
    assert min(abs(z - 1.72) for z in report.floors) < 0.01
    floor = world.areas[0].box.lo[2]
    assert floor == pytest.approx(1.723, abs=0.01)
    clutter = place_room(world, world.areas[0].id, 1.0, np.random.default_rng(1))
    assert len(clutter.placed) >= 5
    assert all(p.center[2] - p.size[2] / 2 == pytest.approx(floor) for p in clutter.placed)
