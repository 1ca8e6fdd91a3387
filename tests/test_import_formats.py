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
