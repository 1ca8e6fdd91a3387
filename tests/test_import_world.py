"""An imported world is a normal world: areas searched like rooms, routes round and over its
blocks, the planner's map, the physics, the recording and the mission autzen_recon."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scenes import write_las

from astralis_des import RunResult, Simulation, load_mission
from astralis_des.errors import InputError
from astralis_des.importers import ImportOptions, import_world
from astralis_des.planning.blocks import CLIMB, MARGIN, round_blocks
from astralis_des.planning.occupancy import world_map
from astralis_des.world.build import load_world
from astralis_des.world.geometry import segments_hit_boxes
from astralis_des.world.model import World

ROOT = Path(__file__).resolve().parents[1]
RADIUS = 0.35  # a UAV's body and the planner's margin


def write_world(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "w.yaml"
    path.write_text("name: w\nsite: {size: [50, 40]}\n" + body, encoding="utf-8")
    return path


def test_a_world_of_areas_alone_loads_with_segments_by_id(tmp_path: Path) -> None:
    """Areas need no building; GROUP.LEVEL.SEGMENT.AREA ids group them in segments."""
    world = load_world(write_world(tmp_path, """areas:
  - {id: Z.1.1.1, box: [[1, 1, 0], [11, 11, 8]]}
  - {id: Z.1.1.2, box: [[15, 1, 0], [25, 11, 8]], entry: north}
  - {id: Z.1.2.1, box: [[30, 1, 0], [40, 11, 8]], entry: west}
"""))
    assert world.segment_order("Z") == ["Z.1.1", "Z.1.2"]
    assert world.segments["Z.1.1"].rooms == ("Z.1.1.1", "Z.1.1.2")
    assert world.rooms["Z.1.1.2"].door_point("corridor") == pytest.approx((20.0, 11.6, 0.0))
    assert world.rooms["Z.1.2.1"].door_point("room") == pytest.approx((30.6, 6.0, 0.0))
    assert world.groups == {"Z"}
    way = world.router.route((1.0, 30.0, 0.0), world.rooms["Z.1.1.2"].center, "human")
    assert way is not None and way[-2] == pytest.approx([20.0, 10.4, 0.0])


@pytest.mark.parametrize("body,message", [
    ("areas: []\n", "a world needs buildings, areas or an interior: there is nothing to search"),
    ("areas:\n  - {id: Z.1.1, box: [[1, 1, 0], [9, 9, 8]]}\n", "areas[0].id: String should "
     "match pattern"),
    ("areas:\n  - {id: Z.1.1.1, box: [[1, 1, 0], [60, 9, 8]]}\n", "areas[0].box: area "
     "Z.1.1.1 reaches outside the site (50 x 40 m)"),
    ("areas:\n  - {id: Z.1.1.1, box: [[9, 1, 0], [1, 9, 8]]}\n", "must be below"),
    ("buildings:\n  - {id: Z, origin: [1, 20], floors: 1, segments: [{side: north, rooms: 1}]}"
     "\nareas:\n  - {id: Z.1.1.1, box: [[1, 1, 0], [9, 9, 8]]}\n",
     "areas[0].id: 'Z' is a building's id"),
])
def test_bad_areas_are_refused_with_their_line(tmp_path: Path, body: str, message: str) -> None:
    """Each mistake in an area names the world file, the line and the key."""
    with pytest.raises(InputError) as caught:
        load_world(write_world(tmp_path, body))
    assert message in str(caught.value) and str(caught.value).startswith(str(tmp_path))


@pytest.fixture(scope="module")
def walled(tmp_path_factory: pytest.TempPathFactory) -> World:
    """A flat 60 m x 40 m site with a tower (4 m x 4 m, 12 m high) and a long low wall
    (across the whole site at y = 30, 3 m high), imported from a cloud."""
    folder = tmp_path_factory.mktemp("walled")
    gx, gy = np.meshgrid(np.arange(0, 60.01, 0.5), np.arange(0, 40.01, 0.5))
    ground = np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)])
    tx, ty, tz = np.meshgrid(np.arange(28, 32.01, 0.4), np.arange(8, 12.01, 0.4),
                             np.arange(0.4, 12.01, 0.4))
    wx, wz = np.meshgrid(np.arange(0, 60.01, 0.4), np.arange(0.4, 3.01, 0.4))
    wall = np.column_stack([wx.ravel(), np.full(wx.size, 30.0), wz.ravel()])
    tower = np.column_stack([tx.ravel(), ty.ravel(), tz.ravel()])
    points = np.vstack([ground, tower, wall])
    classes = np.concatenate([np.full(len(ground), 2), np.full(len(tower) + len(wall), 1)])
    write_las(folder / "walled.las", points, classes.astype(np.uint8))
    import_world(folder / "walled.las", folder / "walled.yaml",
                 ImportOptions(voxel=0.5, margin=0.0, area_size=8.0))
    return load_world((folder / "walled.yaml").resolve())


def clear_of_blocks(world: World, path: np.ndarray) -> bool:
    grown = np.stack([world.block_array[:, 0] - RADIUS, world.block_array[:, 1] + RADIUS], 1)
    return not segments_hit_boxes(path[:-1], path[1:], grown).any()


def test_a_uav_flies_round_a_tower_and_over_a_long_low_wall(walled: World) -> None:
    """Round the tower (shorter than climbing 12 m), over the wall (60 m long, 3 m high);
    a walker goes round the tower and finds no way through the wall."""
    past_tower = np.array([[30.0, 2.0, 4.0], [30.0, 18.0, 4.0]])
    path, _ = round_blocks(walled, past_tower, RADIUS, fly=True, floor=0.0)
    assert path is not None and clear_of_blocks(walled, path)
    assert path[:, 2].max() == pytest.approx(4.0)
    assert np.abs(path[:, 0] - 30.0).max() > 2.0 + RADIUS  # it went round
    across_wall = np.array([[20.0, 25.0, 2.0], [20.0, 35.0, 2.0]])
    path, _ = round_blocks(walled, across_wall, RADIUS, fly=True, floor=0.0)
    assert path is not None and clear_of_blocks(walled, path)
    assert path[:, 2].max() == pytest.approx(3.0 + RADIUS + MARGIN + CLIMB)  # over it
    walk = past_tower - np.array([0.0, 0.0, 3.4])
    path, _ = round_blocks(walled, walk, 0.25, fly=False, floor=0.0)
    assert path is not None and path[:, 2].max() == pytest.approx(0.6)
    path, reason = round_blocks(walled, across_wall - [0, 0, 1.4], 0.25, fly=False, floor=0.0)
    assert path is None and reason == "no way round the blocks to [20.0, 35.0, 0.6]"


def test_the_planner_map_and_the_physics_see_the_blocks(walled: World) -> None:
    """The voxel map is at the import's voxel, occupied in the tower and free beside it; in
    PyBullet a ray down onto the tower stops at its top."""
    from astralis_des.physics.client import PhysicsClient

    vmap = world_map(walled)
    assert vmap.resolution == 0.5
    assert not vmap.free([[30.0, 10.0, 6.0]], 0.1)[0]
    assert vmap.free([[20.0, 10.0, 6.0]], 1.0)[0]
    client = PhysicsClient(walled, 1 / 240, 1, 10)
    try:
        hit = client.call("rayTest", [30.0, 10.0, 30.0], [30.0, 10.0, -1.0])[0]
        assert hit[3][2] == pytest.approx(12.0, abs=0.5)
    finally:
        client.close()


def test_world_show_records_an_imported_world(tmp_path: Path) -> None:
    """``world show`` of the Autzen twin writes a recording with its cloud and blocks."""
    from astralis_des.sinks.world_show import show_world

    shown = show_world(ROOT / "worlds" / "autzen.yaml", [0.1], tmp_path / "autzen.rrd")
    assert shown.rooms == 4 and shown.path.stat().st_size > 400_000


Run = tuple[Simulation, RunResult]


@pytest.fixture(scope="module")
def recon() -> tuple[Run, Run]:
    mission = load_mission(ROOT / "missions" / "autzen_recon.yaml")
    kinematic = Simulation(mission)
    physics = Simulation(mission.with_changes(fidelity="physics"))
    return (kinematic, kinematic.run()), (physics, physics.run())


def test_autzen_recon_flies_round_the_trees_to_every_area(recon: tuple[Run, Run]) -> None:
    """The two UAVs search the areas segment by segment; no leg they fly in the kinematic
    fidelity comes within their body of a block of the scan."""
    (sim, result), _ = recon
    assert [r["segment"] for r in result.rounds] == ["S.1.1", "S.1.2"]
    assert sorted(m["agent"] for m in result.rounds[0]["matching"]) == ["uav1", "uav2"]
    for robot in sim.robots.values():
        assert clear_of_blocks(sim.world, np.array(robot.trail_p))
    first = next(e for e in result.events if e["kind"] == "task_finished")
    start = np.array(next(m.start for m in sim.mission.spec.team if m.id == first["robot"]))
    door = np.array(sim.world.rooms[first["room"]].door_point("corridor"))
    assert first["action"] == "move" and first["distance"] > np.linalg.norm(door - start) + 1.0


def test_autzen_recon_is_the_same_mission_in_physics(recon: tuple[Run, Run]) -> None:
    """Physics gives the same rounds, the same finder, and no failed task."""
    (_, kinematic), (_, physics) = recon
    assert [r["matching"] for r in physics.rounds] == [
        [{**m, "cost": pytest.approx(m["cost"], abs=0.05)} for m in r["matching"]]
        for r in kinematic.rounds]
    assert physics.outcome == kinematic.outcome == "found"
    assert physics.found_by == kinematic.found_by
    assert not [e for e in physics.events  # (tasks still running at the end: cancelled)
                if e["kind"] == "task_finished" and e["status"] != "succeeded"
                and e["message"] != "mission ended"]
