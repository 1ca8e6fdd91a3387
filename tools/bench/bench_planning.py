"""Planning benchmark on the default world: map build, UAV plans in 3-D, UGV plans in SE2.

    python tools/bench/bench_planning.py [--plans 30] [--budget 5] [--seed 0]

(a) UAV in 3-D: from a random outdoor point 5-20 m from building A to the centre of a random
    third-floor room of A (through the entrance, the stairwell and a 1 m door), planned as a
    mission plans it (the navigator in map mode: the rooms-and-doors graph finds the way, the
    lintels and the voxel map shape it, OMPL plans only legs a straight line cannot take); for
    comparison OMPL's RRTConnect alone on the whole way (1.5 m up to 1.5 m over the room's
    floor), with its range at 5 m and at OMPL's default, and on the leg a navigator would hand
    it, from the corridor in front of the room's door to its centre, within 3 m of the line.
(b) UGV, RRTConnect in Reeds-Shepp space on a floor slice of A: from a random corridor point to
    the corridor-side door point of a random room on that floor, facing the door.
(c) the voxel map of the world (0.2 m): built afresh, median of a few builds.

A failed plan counts at the time it took (its whole budget, unless it failed before planning).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.planning.occupancy import GridMap, VoxelMap, world_map  # noqa: E402
from astralis_des.planning.ompl_adapter import Plan, plan_3d, plan_se2  # noqa: E402
from astralis_des.world.build import load_world  # noqa: E402
from astralis_des.world.model import World  # noqa: E402

GOAL_MS = 50.0
BUILD_GOAL_S = 1.5
UAV_RADIUS = 0.35  # m, body and margin
UGV_RADIUS = 0.35
TURNING_RADIUS = 0.4
WINDOW = 3.0  # m around a leg, as a navigator bounds it
MAX_STEP = 5.0  # m, RRTConnect's range for the building (OMPL's default: 9 m here)


def report(name: str, plans: list[Plan], goal_ms: float | None = GOAL_MS) -> None:
    ms = np.array([1000 * p.seconds for p in plans])
    solved = sum(p.ok for p in plans)
    median, p90 = float(np.median(ms)), float(np.percentile(ms, 90))
    verdict = "" if goal_ms is None else \
        f"; goal < {goal_ms:g} ms median: {'ok' if median < goal_ms else 'NOT MET'}"
    print(f"{name}: solved {solved}/{len(plans)}, median {median:.1f} ms, p90 {p90:.1f} ms"
          f"{verdict}")
    reasons = sorted({p.reason for p in plans if not p.ok})
    for reason in reasons:
        print(f"    failed: {reason} x {sum(p.reason == reason for p in plans)}")


def outdoor_start(world: World, vmap: VoxelMap, rng: np.random.Generator) -> np.ndarray:
    box = world.buildings["A"].footprint
    lo, hi = np.array(box.lo[:2]), np.array(box.hi[:2])
    while True:
        point = np.array([*rng.uniform(lo - 20, hi + 20), 1.5])
        gap = np.maximum(np.maximum(lo - point[:2], point[:2] - hi), 0.0)
        if 5.0 <= np.hypot(*gap) <= 20.0 and vmap.free(point, UAV_RADIUS)[0]:
            return point


def bench_uav(world: World, vmap: VoxelMap, args: argparse.Namespace) -> None:
    rng = np.random.default_rng(args.seed)
    rooms = [r for r in world.rooms.values() if r.building == "A" and r.floor == 3]
    box = world.buildings["A"].footprint
    valid: Callable[[np.ndarray], np.ndarray] = lambda p: vmap.free(p, UAV_RADIUS)  # noqa: E731
    steps: dict[float | None, list[Plan]] = {MAX_STEP: [], None: []}
    legs, queries = [], []
    for k in range(args.plans):
        room = rooms[rng.integers(len(rooms))]
        cx, cy, _ = room.box.center
        goal = np.array([cx, cy, room.box.lo[2] + 1.5])
        start = outdoor_start(world, vmap, rng)
        queries.append((start - [0.0, 0.0, 1.5], goal - [0.0, 0.0, 1.5]))
        lo = np.minimum(np.array(box.lo), start) - [3.0, 3.0, 0.0]
        hi = np.maximum(np.array(box.hi), start) + [3.0, 3.0, 1.0]
        for step, plans in steps.items():
            plans.append(plan_3d(valid, lo, hi, start, goal, budget=args.budget,
                                 seed=args.seed + k, resolution=0.1, max_step=step))
        door = np.array(room.door_point("corridor")) + [0.0, 0.0, 1.5]
        legs.append(plan_3d(valid, np.minimum(door, goal) - WINDOW,
                            np.maximum(door, goal) + WINDOW, door, goal, budget=args.budget,
                            seed=args.seed + k, resolution=0.1))
    navigator_routes(queries)
    for step, plans in steps.items():
        what = "OMPL's default" if step is None else f"{step:g} m"
        report(f"(a) UAV 3-D, OMPL alone on the whole way, max step {what}", plans, None)
    report("(a) UAV 3-D, leg: corridor at the door -> room centre", legs)


def navigator_routes(queries: list[tuple[np.ndarray, np.ndarray]]) -> None:
    """(a) as a physics mission plans it: the navigator in map mode, the rooms empty as the
    voxel map of (a) is. Each route's wall time (the map is built before the first)."""
    from astralis_des import Simulation, load_mission

    mission = load_mission(ROOT / "missions" / "urban_search.yaml")
    mission = mission.with_changes(fidelity="physics", rooms={"set": {
        r: {"messiness": 0.0} for r in mission.world.rooms}})
    sim = Simulation(mission)
    robot = sim.robots["uav1"]
    sim.navigator.map  # noqa: B018  (built once per world: (c) times it)
    times, failed = [], 0
    for start, goal in queries:
        t0 = time.perf_counter()
        route = sim.navigator.route(robot, start, goal)
        times.append(time.perf_counter() - t0)
        failed += route.points is None
    ms = np.array(times) * 1e3
    median, p90 = float(np.median(ms)), float(np.percentile(ms, 90))
    verdict = "ok" if median < GOAL_MS and p90 < 150 else "NOT MET"
    print(f"(a) UAV 3-D, outdoors -> third-floor room of A, as a mission plans it: solved "
          f"{len(queries) - failed}/{len(queries)}, median {median:.1f} ms, p90 {p90:.1f} ms; "
          f"goal < {GOAL_MS:g} ms median and p90 < 150 ms: {verdict}; "
          f"{sim.navigator.plans} legs planned with OMPL")


def free_xy(grid: GridMap, poses: np.ndarray) -> np.ndarray:
    return grid.free(poses[:, :2], UGV_RADIUS)


def bench_ugv(world: World, vmap: VoxelMap, args: argparse.Namespace) -> None:
    rng = np.random.default_rng(args.seed)
    plans = []
    for k in range(args.plans):
        floor = int(rng.integers(1, world.buildings["A"].floors + 1))
        corridor = world.spaces[f"A.{floor}.corridor"].box
        level = corridor.lo[2]
        grid = vmap.slice_2d(level + 0.3, level + 1.2)
        rooms = [r for r in world.rooms.values() if r.building == "A" and r.floor == floor]
        room = rooms[rng.integers(len(rooms))]
        door = np.array(room.door_point("corridor"))
        facing = np.arctan2(*(np.array(room.box.center[:2]) - door[:2])[::-1])
        y_mid = (corridor.lo[1] + corridor.hi[1]) / 2
        start = np.array([rng.uniform(corridor.lo[0] + 1, corridor.hi[0] - 1), y_mid,
                          rng.choice([0.0, np.pi])])
        lo2 = np.array(corridor.lo[:2]) - 1.0
        hi2 = np.array(corridor.hi[:2]) + 1.0
        plans.append(plan_se2(partial(free_xy, grid), lo2, hi2, start,
                              np.array([door[0], door[1], facing]),
                              turning_radius=TURNING_RADIUS, budget=args.budget,
                              seed=args.seed + k, resolution=0.05))
    report("(b) UGV SE2 Reeds-Shepp, corridor -> door point, same floor", plans)


def bench_map(world: World, repeat: int) -> None:
    times = []
    for _ in range(repeat):
        world.__dict__.pop("_voxel_map", None)
        t0 = time.perf_counter()
        vmap = world_map(world)
        times.append(time.perf_counter() - t0)
    median = statistics.median(times)
    shape = " x ".join(map(str, vmap.occupied.shape))
    verdict = "ok" if median < BUILD_GOAL_S else "TOO SLOW"
    print(f"(c) voxel map at 0.2 m ({shape} voxels): median {median:.3f} s of {repeat} "
          f"(min {min(times):.3f}, max {max(times):.3f}); goal < {BUILD_GOAL_S:g} s: {verdict}")


def bench_navigator(args: argparse.Namespace) -> None:
    """(d) What a mission in map mode does: the rooms-and-doors graph finds the way, OMPL
    plans only the legs furniture blocks. UAV from outdoors to third-floor rooms of A, every
    room furnished at messiness 1."""
    from astralis_des import Simulation, load_mission

    mission = load_mission(ROOT / "missions" / "urban_search.yaml")
    mission = mission.with_changes(planning={"method": "map", "budget": args.budget},
                                   rooms={"set": {r: {"messiness": 1.0}
                                                  for r in mission.world.rooms}})
    sim = Simulation(mission)
    robot = sim.robots["uav1"]
    rng = np.random.default_rng(args.seed)
    rooms = [r for r in sorted(sim.world.rooms) if r.startswith("A.3.")]
    times, failures = [], 0
    for _ in range(args.plans):
        room = sim.world.rooms[rooms[int(rng.integers(len(rooms)))]]
        sim.scene.clutter(room.id)  # furnished before planning, as an action does
        start = np.array([rng.uniform(40, 100), rng.uniform(40, 60), 0.0])
        t0 = time.perf_counter()
        route = sim.navigator.route(robot, start, np.array(room.center))
        times.append((time.perf_counter() - t0) * 1e3)
        failures += route.points is None
    print(f"(d) UAV route, graph + OMPL on blocked legs (furnished at messiness 1): "
          f"median {statistics.median(times):.1f} ms, p90 {np.percentile(times, 90):.1f} ms "
          f"(goal < {GOAL_MS:.0f} ms); {sim.navigator.plans} legs planned, "
          f"{failures} of {args.plans} routes failed")


def bench_coverage() -> None:
    """(e) Share of each room's free floor a UAV's search pattern sees, over the 18 rooms of
    building A, empty (messiness 0) and furnished at messiness 1."""
    from astralis_des import Simulation, load_mission
    from astralis_des.actions.common import footprint_spacing, plane_to_floor
    from astralis_des.world import coverage as cov

    base = load_mission(ROOT / "missions" / "urban_search.yaml")
    patterns = {
        "spiral_inward": lambda box, s: cov.spiral(box, s, True),
        "spiral_outward": lambda box, s: cov.spiral(box, s, False),
        "sweep_horizontal": lambda box, s: cov.lawnmower(box, s, 0),
        "sweep_vertical": lambda box, s: cov.lawnmower(box, s, 1),
    }
    for messiness in (0.0, 1.0):
        sim = Simulation(base.with_changes(rooms={"set": {
            r: {"messiness": messiness} for r in base.world.rooms}}))
        uav = sim.robots["uav1"]
        spacing = footprint_spacing(uav, 0.2)
        shares = {}
        for name, make in patterns.items():
            values = []
            for rid in sorted(r for r in sim.world.rooms if r.startswith("A.")):
                room = sim.world.rooms[rid]
                plan = plane_to_floor(room, make(room.box, spacing)) + [0, 0, uav.height]
                values.append(sim.sensor.coverage(uav, plan, room))
            shares[name] = (statistics.mean(values), min(values))
        text = ", ".join(f"{k} {m:.1%} (min {lo:.1%})" for k, (m, lo) in shares.items())
        goal = " (goal >= 90%)" if messiness == 0 else " (reported)"
        print(f"(e) coverage of free floor at messiness {messiness:g}{goal}: {text}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--plans", type=int, default=30)
    parser.add_argument("--budget", type=float, default=5.0, help="s per plan")
    parser.add_argument("--builds", type=int, default=5)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    world = load_world(ROOT / "worlds" / "urban_default.yaml")
    bench_map(world, args.builds)
    vmap = world_map(world)
    bench_ugv(world, vmap, args)
    bench_uav(world, vmap, args)
    bench_navigator(args)
    bench_coverage()


if __name__ == "__main__":
    main()
