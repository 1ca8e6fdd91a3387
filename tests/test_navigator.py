"""Navigation: the graph's way, refined around furniture on the map; failures as reasons."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from astralis_des import Mission, Simulation, load_mission
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.world.clutter import Clutter, Placed

ROOT = Path(__file__).resolve().parents[1]


def mission(**planning: object) -> Mission:
    base = load_mission(ROOT / "missions" / "fig7.yaml")
    return base.with_changes(planning={"method": "map", **planning})


def furnished(sim: Simulation, room: str, *items: Placed) -> None:
    sim.scene.set_clutter(room, Clutter(items, ()))


def clear_everywhere(sim: Simulation, kind: str, points: np.ndarray) -> bool:
    """Every point 5 cm apart along the path keeps the body clear (map and furniture)."""
    robot = next(r for r in sim.robots.values() if r.kind == kind)
    dense = [points[0]]
    for a, b in itertools.pairwise(points):
        n = max(2, int(np.ceil(np.linalg.norm(b - a) / 0.05)) + 1)
        dense.extend(a + (b - a) * np.linspace(0, 1, n)[1:, None])
    dense_arr = np.array(dense)
    if kind != "uav":
        dense_arr[:, 2] = sim.world.floor_below(dense_arr[0]) + 0.4
    radius = KIND_DEFAULTS[kind].radius + sim.mission.spec.planning.margin
    cell = 0.1 if kind != "uav" else 0.2  # the planner's grid: clear to within a cell
    return bool(sim.navigator._valid(robot, dense_arr, radius - cell).all())


def test_graph_mode_keeps_the_graphs_straight_legs() -> None:
    """Kinematic missions plan on the rooms-and-doors graph: the route is the router's, at
    the flight height but where a UAV ducks under a door's lintel (by a doorway)."""
    sim = Simulation(load_mission(ROOT / "missions" / "fig7.yaml"))
    robot = sim.robots["uav1"]
    goal = np.array(sim.world.rooms["A.1.1.2"].center)
    start = sim.world.on_floor(robot.pose)
    route = sim.navigator.route(robot, start, goal)
    expected = sim.world.router.route(start, goal, "uav")
    assert sim.navigator.method == "graph"
    points = route.points
    assert {tuple(p) for p in np.round(expected[:, :2], 6)} == {
        tuple(p) for p in np.round(points[:, :2], 6)}  # the graph's points, in the plane
    low = points[:, 2] < robot.height - 1e-9
    assert low.any() and np.all(points[~low, 2] == pytest.approx(robot.height))
    doors = sim.world.doorways[:, :2]
    near = np.linalg.norm(points[low, None, :2] - doors[None], axis=2).min(axis=1)
    assert np.all(near < 2.0) and np.all(points[low, 2] > 1.0)  # the points either side


@pytest.mark.parametrize("kind", ["uav", "human", "ugv"])
def test_a_blocked_leg_is_planned_around_the_furniture(kind: str) -> None:
    """A cabinet 2 m tall across a leg in a room: the refined path goes round it, clear."""
    sim = Simulation(mission())
    room = sim.world.rooms["A.1.1.2"]
    floor = room.box.lo[2]
    x = room.center[0]
    cabinet = Placed("cabinet", room.id, (x, 83.0, floor + 1.0), (1.0, 0.5, 2.0), 0.0)
    furnished(sim, room.id, cabinet)
    robot = next(r for r in sim.robots.values() if r.kind == kind)
    a = np.array([x, 81.0, floor + robot.height])
    b = np.array([x, 85.0, floor + robot.height])
    assert not sim.navigator._leg_free(robot, a, b, 0.4)
    route = sim.navigator.refine(robot, np.array([a, b]))
    assert route.points is not None, route.reason
    assert len(route.points) > 2
    assert np.allclose(route.points[0], a) and np.allclose(route.points[-1][:2], b[:2])
    assert clear_everywhere(sim, kind, route.points)
    assert sim.navigator.plans == 1


def test_a_goal_inside_an_obstacle_is_a_reason_not_a_crash() -> None:
    """Asked to go into a parked vehicle: no route, and the reason says where."""
    sim = Simulation(mission())
    robot = sim.robots["op1"]
    route = sim.navigator.route(robot, robot.pose - [0, 0, robot.height],
                                np.array([100.0, 62.0, 0.0]))
    assert route.points is None
    assert "inside a building or obstacle" in route.reason


def test_a_zero_budget_fails_a_leg_that_needs_planning() -> None:
    """With planning.budget 0, a leg needing a detour fails, naming the budget."""
    sim = Simulation(mission(budget=0.0))
    room = sim.world.rooms["A.1.1.2"]
    floor = room.box.lo[2]
    x = room.center[0]
    furnished(sim, room.id,
              Placed("cabinet", room.id, (x, 83.0, floor + 1.0), (1.0, 0.5, 2.0), 0.0))
    robot = sim.robots["uav1"]
    route = sim.navigator.refine(robot, np.array([[x, 81.0, floor + 1.5], [x, 85.0, floor + 1.5]]))
    assert route.points is None and "budget" in route.reason


def test_a_failed_route_fails_the_task_and_the_mission_goes_on() -> None:
    """A commanded move into a vehicle fails with its reason; the search carries on. (In a
    mission's timeline such a point is refused when the file loads: test_world_values.py;
    a command given while the mission runs, as the API and the chat give them, is not.)"""
    sim = Simulation(mission())
    sim.enqueue("op1", "move", None, {"x": 100.0, "y": 62.0}, origin="command")
    result = sim.run()
    failed = [e for e in result.events if e["kind"] == "task_finished" and e["robot"] == "op1"]
    assert failed[0]["status"] == "failed"
    assert "inside a building or obstacle" in failed[0]["message"]
    assert result.outcome == "found"


def test_the_map_is_in_the_recording_when_used(tmp_path: Path) -> None:
    """A physics run that planned on the voxel map records its occupied voxels, once."""
    import shutil
    import subprocess

    sim = Simulation(load_mission(ROOT / "missions" / "fig7.yaml").with_changes(
        fidelity="physics"), out_dir=tmp_path)
    sim.run()
    assert sim.navigator.map_built
    points = sim.navigator.occupied_points()
    assert len(points) > 100_000 and points[:, 2].min() > 0.0
    rrd = tmp_path / "recording.rrd"
    assert rrd.stat().st_size > 500_000  # 150k points (compressed), logged once
    if shutil.which("rerun"):
        assert subprocess.run(["rerun", "rrd", "verify", str(rrd)],
                              capture_output=True).returncode == 0
