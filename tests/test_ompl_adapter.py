"""OMPL behind the adapter: paths in 3-D and SE2, failures as reasons, same seed same path."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from astralis_des.planning.occupancy import GridMap, VoxelMap, from_boxes, world_map
from astralis_des.planning.ompl_adapter import Plan, plan_3d, plan_se2
from astralis_des.world.model import World

UAV = 0.35  # m of clearance around a UAV
UGV = 0.35
TURN = 0.5  # m, the UGV's turning radius

# A 10 m x 10 m x 3 m hall split by two walls, each with a gap at the opposite end.
MAZE_WALLS = np.array([
    [[3.0, 0.0, 0.0], [3.2, 7.0, 3.0]],
    [[6.5, 3.0, 0.0], [6.7, 10.0, 3.0]],
])
MAZE_LO, MAZE_HI = (0.0, 0.0, 0.0), (10.0, 10.0, 3.0)


def maze_plan(kind: str, seed: int) -> Plan:
    """The reference problems of the determinism tests (also run in a fresh process)."""
    maze = from_boxes(MAZE_WALLS, MAZE_LO, MAZE_HI, 0.2)
    if kind == "se2":
        floor = maze.slice_2d(0.5, 1.0)
        return plan_se2(lambda s: floor.free(s[:, :2], 0.3), (0, 0), (10, 10), (1, 1, 0),
                        (9, 9, np.pi / 2), turning_radius=0.5, budget=10.0, seed=seed)
    return plan_3d(lambda p: maze.free(p, 0.3), MAZE_LO, MAZE_HI, (1, 1, 1.5), (9, 9, 1.5),
                   budget=10.0, seed=seed, planner=kind, iterations=300)


@pytest.fixture(scope="module")
def vmap(world: World) -> VoxelMap:
    return world_map(world)


@pytest.fixture(scope="module")
def second_floor(vmap: VoxelMap) -> GridMap:
    return vmap.slice_2d(3.5 + 0.3, 3.5 + 1.2)


def test_a_uav_flies_from_outdoors_into_a_third_floor_room(
        world: World, vmap: VoxelMap) -> None:
    """Through the entrance, up the stairwell and through a door: free, ending at the goal."""
    room = world.rooms["A.3.1.2"]
    cx, cy, _ = room.box.center
    goal = np.array([cx, cy, room.box.lo[2] + 1.5])
    start = np.array([20.0, 20.0, 1.5])
    plan = plan_3d(lambda p: vmap.free(p, UAV), (15, 15, 0), (85, 90, 12.5), start, goal,
                   budget=300.0, seed=5, max_step=5.0)  # it stops at its first path
    assert plan.ok and plan.reason == "" and plan.path is not None
    assert np.array_equal(plan.path[0], start) and np.array_equal(plan.path[-1], goal)
    assert vmap.path_free(plan.path, UAV, step=0.05)
    steps = np.linalg.norm(np.diff(plan.path, axis=0), axis=1)
    assert steps.max() <= 1.0 + 1e-9
    assert plan.length == pytest.approx(steps.sum())
    assert plan.length > np.linalg.norm(goal - start)
    assert 0.0 < plan.seconds < 300.0


def test_a_ugv_turns_no_tighter_than_its_radius(world: World, second_floor: GridMap) -> None:
    """Reeds-Shepp on the second floor: free poses, dense, heading changing at most 1/r."""
    room = world.rooms["A.2.1.3"]
    door = room.door_point("corridor")
    corridor = world.spaces["A.2.corridor"].box
    start = (corridor.lo[0] + 1.5, (corridor.lo[1] + corridor.hi[1]) / 2, 0.0)
    goal = (door[0], door[1], np.pi / 2)  # facing the door
    plan = plan_se2(lambda s: second_floor.free(s[:, :2], UGV), (58, 68), (82, 88), start, goal,
                    turning_radius=TURN, budget=120.0, seed=3)
    assert plan.ok and plan.path is not None
    path = plan.path
    assert np.allclose(path[0], start) and np.allclose(path[-1], goal)
    assert second_floor.free(path[:, :2], UGV).all()
    arc = np.linalg.norm(np.diff(path[:, :2], axis=0), axis=1)
    assert arc.max() <= 0.25 + 1e-9
    turn = np.abs((np.diff(path[:, 2]) + np.pi) % (2 * np.pi) - np.pi)
    assert np.all(turn <= arc / TURN * 1.03 + 1e-9)
    assert plan.length == pytest.approx(arc.sum(), rel=0.01)


def test_a_dubins_car_only_drives_forward(world: World, second_floor: GridMap) -> None:
    """In Dubins space each step goes the way the car faces."""
    corridor = world.spaces["A.2.corridor"].box
    y = (corridor.lo[1] + corridor.hi[1]) / 2
    plan = plan_se2(lambda s: second_floor.free(s[:, :2], UGV), (58, 68), (82, 88),
                    (corridor.lo[0] + 1.5, y, 0.0), (corridor.hi[0] - 2.0, y, 0.0),
                    turning_radius=TURN, budget=120.0, space="dubins",
                    seed=1)
    assert plan.ok and plan.path is not None
    step = np.diff(plan.path[:, :2], axis=0)
    heading = np.column_stack([np.cos(plan.path[:-1, 2]), np.sin(plan.path[:-1, 2])])
    assert np.all((step * heading).sum(axis=1) > 0)


def test_a_goal_or_start_inside_a_wall_is_refused(world: World, vmap: VoxelMap) -> None:
    """A pose in a wall fails at once, saying which end is in collision."""
    x, y, _ = world.rooms["A.1.1.1"].door.center
    in_wall = (x + 1.0, y, 1.0)
    free = (x, y - 1.5, 1.0)
    valid = lambda p: vmap.free(p, UAV)  # noqa: E731
    goal_hit = plan_3d(valid, (55, 65, 0), (90, 90, 12), free, in_wall, budget=1.0, seed=0)
    start_hit = plan_3d(valid, (55, 65, 0), (90, 90, 12), in_wall, free, budget=1.0, seed=0)
    assert (goal_hit.ok, goal_hit.reason, goal_hit.path) == (False, "goal in collision", None)
    assert (start_hit.ok, start_hit.reason) == (False, "start in collision")
    assert goal_hit.seconds < 0.5
    grid = vmap.slice_2d(0.3, 1.2)
    se2 = plan_se2(lambda s: grid.free(s[:, :2], UGV), (55, 65), (90, 90), (*free[:2], 0.0),
                   (*in_wall[:2], 0.0), turning_radius=TURN, budget=1.0, seed=0)
    assert se2.reason == "goal in collision"


def test_a_budget_that_is_not_positive_is_refused() -> None:
    """Budget 0 (or less) fails before OMPL is asked, naming the budget."""
    free = lambda p: np.ones(len(p), dtype=bool)  # noqa: E731
    for budget in (0.0, -1.0):
        plan = plan_3d(free, (0, 0, 0), (5, 5, 5), (1, 1, 1), (4, 4, 4), budget=budget)
        assert not plan.ok and plan.reason.startswith("time budget must be positive")
        se2 = plan_se2(free, (0, 0), (5, 5), (1, 1, 0), (4, 4, 0), turning_radius=1.0,
                       budget=budget)
        assert se2.reason == plan.reason


def test_an_unreachable_goal_fails_within_the_budget() -> None:
    """A goal shut in a closed box: no path, reported once the budget is spent."""
    shell = np.array([
        [[6, 6, 0], [9, 9, 0.2]], [[6, 6, 2.8], [9, 9, 3]],
        [[6, 6, 0], [6.2, 9, 3]], [[8.8, 6, 0], [9, 9, 3]],
        [[6, 6, 0], [9, 6.2, 3]], [[6, 8.8, 0], [9, 9, 3]],
    ], dtype=float)
    boxed = from_boxes(shell, (0, 0, 0), (10, 10, 3), 0.2)
    t0 = time.perf_counter()
    plan = plan_3d(lambda p: boxed.free(p, 0.3), (0, 0, 0), (10, 10, 3), (1, 1, 1.5),
                   (7.5, 7.5, 1.5), budget=0.3, seed=0)
    elapsed = time.perf_counter() - t0
    assert (plan.ok, plan.reason) == (False, "no path found within 0.3 s")
    assert 0.3 <= plan.seconds <= elapsed < 0.3 + 5.0  # (a loaded machine answers late)


def test_an_unknown_planner_is_a_bad_request() -> None:
    """A misspelt planner raises, listing the planners there are."""
    with pytest.raises(ValueError, match="rrtconnect, informed_rrtstar"):
        plan_3d(lambda p: np.ones(len(p), dtype=bool), (0, 0, 0), (1, 1, 1), (0, 0, 0),
                (1, 1, 1), budget=1.0, planner="rrt_connect")


@pytest.mark.parametrize("kind", ["rrtconnect", "informed_rrtstar", "se2"])
def test_the_same_seed_gives_the_same_path_in_any_process(kind: str) -> None:
    """Five runs here and one in a fresh interpreter give identical arrays."""
    plans = [maze_plan(kind, seed=11) for _ in range(5)]
    assert all(p.ok and p.path is not None for p in plans)
    first = plans[0].path
    assert first is not None and len(first) > 2
    assert all(np.array_equal(np.asarray(p.path), first) for p in plans[1:])
    code = (f"import sys, json; sys.path.insert(0, {str(Path(__file__).parent)!r}); "
            f"from test_ompl_adapter import maze_plan; "
            f"print(json.dumps(maze_plan({kind!r}, 11).path.tolist()))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=Path(__file__).parents[1])
    assert np.array_equal(np.array(json.loads(out.stdout.strip().splitlines()[-1])), first)


def test_another_seed_gives_another_path() -> None:
    """The seed is what the path depends on."""
    a, b = maze_plan("rrtconnect", seed=1), maze_plan("rrtconnect", seed=2)
    assert a.path is not None and b.path is not None
    assert not (a.path.shape == b.path.shape and np.array_equal(a.path, b.path))
