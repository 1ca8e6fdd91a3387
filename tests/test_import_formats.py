"""Every format a world can be imported from, with small files the tests write: what the
world holds afterwards (site, blocks where the building stands, free ground, floors, areas)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from scenes import (
    BUILDING,
    FT_WKT,
    GROUND_Z,
    SIZE,
    cloud_points,
    scene_mesh,
    write_las,
    write_mesh,
    write_pcd,
    write_ply,
    write_text,
    y_up,
)

from astralis_des.importers import ImportOptions, formats, import_world
from astralis_des.world.build import load_world
from astralis_des.world.model import World

ROOT = Path(__file__).resolve().parents[1]
MARGIN = 2.0
VOXEL = 0.5
OPTIONS = ImportOptions(voxel=VOXEL, margin=MARGIN, area_size=10.0)

CLOUD_WRITERS: dict[str, Callable[[Path, np.ndarray, np.ndarray], Path]] = {
    "las": lambda p, pts, cls: write_las(p, pts, cls),
    "laz": lambda p, pts, cls: write_las(p, pts, cls),
    "ply_ascii": lambda p, pts, cls: write_ply(p.with_suffix(".ply"), pts, ascii=True),
    "ply_binary": lambda p, pts, cls: write_ply(p.with_suffix(".ply"), pts, ascii=False),
    "pcd_ascii": lambda p, pts, cls: write_pcd(p.with_suffix(".pcd"), pts, binary=False),
    "pcd_binary": lambda p, pts, cls: write_pcd(p.with_suffix(".pcd"), pts, binary=True),
    "xyz": lambda p, pts, cls: write_text(p, pts),
    "csv": lambda p, pts, cls: write_text(p, np.column_stack([pts, cls]),
                                          header="x,y,z,classification", delimiter=","),
}


def imported(tmp_path: Path, source: Path, options: ImportOptions = OPTIONS) -> World:
    import_world(source, tmp_path / "out" / "twin.yaml", options)
    return load_world((tmp_path / "out" / "twin.yaml").resolve())


@pytest.mark.parametrize("kind", list(CLOUD_WRITERS))
def test_each_cloud_format_becomes_a_world_with_its_building_as_blocks(
        tmp_path: Path, kind: str) -> None:
    """The building stands where it stood (walls block sight), the ground is free, the site
    is the cloud's extent plus the margin, and areas lie on the open ground."""
    points, classes = cloud_points()
    ext = kind.split("_")[0]
    source = CLOUD_WRITERS[kind](tmp_path / f"scene.{ext}", points, classes)
    world = imported(tmp_path, source)
    assert world.site == pytest.approx((SIZE[0] + 2 * MARGIN, SIZE[1] + 2 * MARGIN), abs=VOXEL)
    (x0, y0), (x1, y1), height = BUILDING
    middle = np.array([(x0 + x1) / 2 + MARGIN, (y0 + y1) / 2 + MARGIN, 2.0])
    outside = middle + np.array([0.0, -10.0, 0.0])
    assert not world.line_of_sight(outside[None], middle[None])[0]  # a wall in the way
    assert world.line_of_sight(outside[None], outside[None] + [[-5.0, 0.0, 0.0]])[0]
    tops = world.block_array[:, 1, 2]
    assert tops.max() == pytest.approx(height, abs=VOXEL)
    assert len(world.areas) == 4
    for area in world.areas:
        assert area.box.lo[2] == 0.0
        assert not np.all((world.block_array[:, 0, :2] < area.box.hi[:2]) &
                          (world.block_array[:, 1, :2] > area.box.lo[:2]), axis=1).any()


def test_ground_share_follows_the_classification_or_the_grid_estimate(tmp_path: Path) -> None:
    """With classes the ground is class 2; without, the grid estimate finds the same points
    (a flat ground, a building on it)."""
    points, classes = cloud_points()
    truth = float(np.mean(classes == 2))
    classified = import_world(write_las(tmp_path / "c.las", points, classes),
                              tmp_path / "c.yaml", OPTIONS)
    estimated = import_world(write_text(tmp_path / "e.xyz", points), tmp_path / "e.yaml",
                             OPTIONS)
    ransac = import_world(write_text(tmp_path / "r.xyz", points), tmp_path / "r.yaml",
                          ImportOptions(voxel=VOXEL, margin=MARGIN, ground="ransac"))
    assert classified.ground == "classification"
    assert classified.ground_share == pytest.approx(truth)
    assert estimated.ground == "grid" and estimated.classified_share is None
    assert estimated.ground_share == pytest.approx(truth, abs=0.005)
    assert ransac.ground_share == pytest.approx(truth, abs=0.005)


def test_units_come_from_the_header_crs_or_the_option(tmp_path: Path) -> None:
    """A LAS in feet (its WKT says so) is scaled to metres; --units overrides; a text cloud
    has no CRS and is taken as metres unless told."""
    points, classes = cloud_points()
    feet = write_las(tmp_path / "ft.las", points, classes, wkt=FT_WKT)
    auto = import_world(feet, tmp_path / "a.yaml", OPTIONS)
    assert auto.scale == pytest.approx(0.3048)
    assert auto.units.startswith("foot") and "WKT" in auto.units
    assert auto.site[0] == pytest.approx(SIZE[0] * 0.3048 + 2 * MARGIN, abs=VOXEL)
    metres = import_world(feet, tmp_path / "m.yaml",
                          ImportOptions(units="m", voxel=VOXEL, margin=MARGIN))
    assert metres.scale == 1.0 and metres.site[0] == pytest.approx(SIZE[0] + 2 * MARGIN,
                                                                    abs=VOXEL)
    text = write_text(tmp_path / "t.xyz", points)
    assert import_world(text, tmp_path / "t.yaml", OPTIONS).scale == 1.0
    told = import_world(text, tmp_path / "f.yaml",
                        ImportOptions(units="ft", voxel=VOXEL, margin=MARGIN))
    assert told.scale == pytest.approx(0.3048) and told.units == "ft (given)"


def test_nan_and_infinite_points_are_dropped_and_counted(tmp_path: Path) -> None:
    """Three bad points out of many: the import goes on and says how many it left out."""
    points, _ = cloud_points()
    bad = points.copy()
    bad[[5, 50, 500]] = [[np.nan, 0, 0], [0, np.inf, 0], [0, 0, -np.inf]]
    report = import_world(write_text(tmp_path / "n.xyz", bad), tmp_path / "n.yaml", OPTIONS)
    assert report.dropped == 3 and report.points == len(points)
    assert "dropped: 3" in (tmp_path / "n.yaml").read_text()


MESH_KINDS = ["obj", "stl", "glb", "gltf", "ply"]


@pytest.mark.parametrize("kind", MESH_KINDS)
def test_each_mesh_format_becomes_a_world_with_its_floors(tmp_path: Path, kind: str) -> None:
    """The ground, the platform's top (1 m) and the house's roof (4 m) are found as floors
    (glTF turned from Y-up); areas stand on them; the closed house is solid inside."""
    mesh = y_up(scene_mesh()) if kind in ("glb", "gltf") else scene_mesh()
    world = imported(tmp_path, write_mesh(tmp_path / f"scene.{kind}", mesh))
    assert world.imported is not None and world.imported.collision == "concave"
    assert world.imported.floors == pytest.approx((0.0, 1.0, 4.0))
    assert {a.box.lo[2] for a in world.areas} == {0.0, 1.0, 4.0}
    platform = next(a for a in world.areas if a.box.lo[2] == 1.0)
    assert platform.box.lo[0] >= 5 + MARGIN - 1e-9 and platform.box.hi[0] <= 15 + MARGIN + 1e-9
    inside_house = np.array([23 + MARGIN, 23 + MARGIN, 2.0])
    assert np.all((inside_house >= world.block_array[:, 0]) &
                  (inside_house <= world.block_array[:, 1]), axis=1).any()
    assert world.imported.vertices is not None
    assert world.imported.vertices.min(axis=0) == pytest.approx([MARGIN, MARGIN, 0.0])


def test_every_registered_extension_is_tested() -> None:
    """The registry's formats are exactly those exercised here and in the real-data tests."""
    assert sorted(formats()) == sorted(["csv", "glb", "gltf", "las", "laz", "obj", "pcd", "ply",
                                        "stl", "txt", "xyz"])


def test_a_classified_aerial_tile_gives_a_solid_building_and_a_canopy_to_walk_under(
        tmp_path: Path) -> None:
    """Issue 24: the classes of an aerial scan are used. The building (class 6, seen as a
    roof and walls) is a solid from its roof to the ground, which a UAV's route goes round;
    a tree's crown (class 5, points 3 to 7 m up) is kept where it is: blocked up there, free
    under it, so a walker passes under it. Noise (class 7) is left out."""
    points, classes = cloud_points()
    tx, ty = 30.0, 22.0  # a tree on the open ground, file frame
    ang, rad = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0.0, 2.0, 8))
    crown = [np.column_stack([tx + (rad * np.cos(ang)).ravel(), ty + (rad * np.sin(ang)).ravel(),
                              np.full(ang.size, GROUND_Z + z)]) for z in np.arange(3.0, 7.01, 0.4)]
    noise = np.array([[5.0, 25.0, GROUND_Z + 30.0]])
    crown_pts = np.vstack(crown)
    points = np.vstack([points, crown_pts, noise])
    classes = np.concatenate([classes, np.full(len(crown_pts), 5), [7]]).astype(np.uint8)
    world = imported(tmp_path, write_las(tmp_path / "tile.las", points, classes))
    blocks = world.block_array

    def blocked(x: float, y: float, z: float) -> bool:
        p = np.array([x + MARGIN, y + MARGIN, z])
        return bool(np.all((blocks[:, 0] <= p) & (blocks[:, 1] >= p), axis=1).any())

    (x0, y0), (x1, y1), height = BUILDING
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    assert all(blocked(cx, cy, z) for z in (0.5, 2.5, height - 0.3))  # solid, not a shell
    assert blocked(tx, ty, 5.0) and blocked(tx + 1.0, ty, 4.0)  # the crown
    assert not blocked(tx, ty, 1.0) and not blocked(tx + 1.0, ty, 2.0)  # free under it
    assert blocks[:, 1, 2].max() == pytest.approx(7.0, abs=VOXEL)  # not the 30 m noise point

    from astralis_des import Simulation, load_mission

    (tmp_path / "out" / "m.yaml").write_text(f"""name: classified
world: twin.yaml
fidelity: physics
team:
  - {{id: uav1, kind: uav, start: [{x0 - 4.0 + MARGIN}, {cy + MARGIN}, 0], height: 2}}
  - {{id: op1, kind: human, start: [{tx - 4.0 + MARGIN}, {ty + MARGIN}, 0]}}
scene: {{clutter: false}}
assignment: {{search: [S]}}
""")
    sim = Simulation(load_mission(tmp_path / "out" / "m.yaml"))
    uav = sim.robots["uav1"]
    start = sim.world.on_floor(uav.pose)
    goal = np.array([x1 + 4.0 + MARGIN, cy + MARGIN, 0.0])
    route = sim.navigator.route(uav, start, goal)
    assert route.points is not None, route.reason
    xy = route.points[:, :2] - MARGIN
    assert np.abs(xy[:, 1] - cy).max() > (y1 - y0) / 2  # it went round the building
    walker = sim.robots["op1"]
    trunk = np.array([tx + MARGIN, ty + MARGIN])
    ring = trunk + 1.0 * np.column_stack([np.cos(np.arange(8)), np.sin(np.arange(8))])
    at = np.column_stack([ring, np.full(8, walker.height)])
    assert sim.navigator.fits(walker, at).all()  # a walker fits under the crown
    high = np.column_stack([ring, np.full(8, 5.0)])
    assert not sim.navigator.fits(uav, high).any()  # a UAV does not fit in it
    sim.finish()
