"""Where a UAV lands when the mission ends: off the loops walkers go round, off the person it
found, out of a room with no free floor by a route to the corridor, never in a doorway; and
in physics the landings of the missions that used to fail them now succeed."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from astralis_des.actions.landing import (
    DOOR_KEEP,
    LANDING_CLEAR,
    LANDING_GRID,
    _free,
    _free_on,
    _Grid,
    landing_way,
)
from astralis_des.simulation import Simulation
from astralis_des.studies import load_study
from astralis_des.studies.eval_mission import scenario_mission

STUDY = Path(__file__).resolve().parents[1] / "studies" / "outcomes_physics.yaml"


def scenario(index: int, strategy: str, fidelity: str = "kinematic") -> Simulation:
    """A scenario of the physics outcome study, as ``bench_fidelity.py`` runs it."""
    study = load_study(STUDY)
    variant = next(v for v in study.variants if v.setting.strategy == strategy)
    mission = scenario_mission(study, study.scenario(index), variant.setting, outputs=False)
    return Simulation(mission.with_changes(fidelity=fidelity))


def hovering(sim: Simulation, rid: str, at: tuple[float, float, float]) -> np.ndarray:
    """The way ``rid`` takes to land from ``at`` (its room furnished, as after a search)."""
    robot = sim.robots[rid]
    room = sim.world.room_at((at[0], at[1], sim.world.floor_below(at) + 0.5))
    if room is not None:
        sim.scene.furnish([room.id])
    robot.pose = np.array(at, dtype=float)
    robot.airborne = True
    return landing_way(sim, robot)


def gap_to_loop(point: np.ndarray, loop: np.ndarray) -> float:
    """The largest of |dx|, |dy| from ``point`` to the nearest point of the loop's legs (the
    square a landing UAV needs meets a walker's box where this is small)."""
    legs = [a + np.outer(np.linspace(0, 1, 200), b - a) for a, b in itertools.pairwise(loop)]
    pts = np.vstack(legs)[:, :2]
    return float(np.abs(pts - point[:2]).max(axis=1).min())


def test_a_uav_lands_on_the_strip_a_patrollers_loop_leaves_free() -> None:
    """Scenario 1 (mixed): uav1 ended its search in A.2.1.2 at the edge of the patroller's
    loop (1.8 x 4.8 m, round a 2 x 5 m room). No spot on its rings is free, and it used to
    come down where it was, in the patroller's way (who then tipped it over). It lands on the
    0.4 m strip inside the loop, clear of the patroller by its square's half-side."""
    sim = scenario(1, "mixed")
    way = hovering(sim, "uav1", (70.71, 81.49, 5.48))
    spot = way[-1]
    assert len(way) == 2 and sim.world.room_at(spot - [0, 0, 1.5]).id == "A.2.1.2"
    (patroller,) = sim.scene.avatar_movers(["A.2.1.2"])
    half = max(patroller.size[:2]) / 2
    assert gap_to_loop(spot, patroller.loop) >= half + LANDING_CLEAR
    assert 69.8 <= spot[0] <= 70.2  # the strip
    assert abs(spot[2] - 5.48) < 1e-9  # it flies there level, then comes down


def test_a_uav_above_the_target_lands_beside_it_not_on_it() -> None:
    """Scenario 27 (greedy): the target stands in A.3.1.1; a UAV right above it lands where
    its square of floor keeps off the target's body."""
    sim = scenario(27, "greedy")
    target = np.asarray(sim.target.start)
    way = hovering(sim, "uav1", (target[0], target[1], 8.94))
    spot = way[-1]
    half = np.asarray(sim.target.size[:2]) / 2 + LANDING_CLEAR
    assert np.any(np.abs(spot[:2] - target[:2]) >= half - 1e-9)


def test_a_uav_in_a_room_without_free_floor_lands_in_the_corridor_by_the_door() -> None:
    """Scenario 27 (greedy): in A.3.1.1 the patroller's loop and the target leave no free
    floor. From the loop's corner uav1 used to fly straight at a spot beyond the wall, by
    the door, and tipped over on the jamb. It now takes a route out through the door and
    lands in the corridor, outside every room, at least DOOR_KEEP from every doorway."""
    sim = scenario(27, "greedy")
    way = hovering(sim, "uav1", (65.13, 80.59, 8.94))
    spot = way[-1]
    floor = sim.world.floor_below(spot)
    assert floor == pytest.approx(7.0)
    assert sim.world.room_at((spot[0], spot[1], floor + 0.5)) is None
    doors = sim.world.doorways
    mine = doors[np.abs(doors[:, 2] - floor) < 1.0]
    assert np.linalg.norm(mine[:, :2] - spot[:2], axis=1).min() >= DOOR_KEEP
    room_door = np.array(sim.world.rooms["A.3.1.1"].door.center[:2])
    assert np.linalg.norm(way[:, :2] - room_door, axis=1).min() < 0.3  # through its door
    assert sim.navigator.fits(sim.robots["uav1"], way).all()


@pytest.mark.parametrize(("index", "strategy"), [(1, "mixed"), (27, "greedy")])
def test_the_landings_that_failed_in_physics_now_succeed(index: int, strategy: str) -> None:
    """The two physics missions of the fidelity benchmark whose UAV tipped over landing (on
    a patroller's loop; flying at a spot past a door jamb, then onto the target): every
    task of the mission ends without failing, and every UAV lands upright."""
    result = scenario(index, strategy, "physics").run()
    failed = [e for e in result.events if e["kind"] == "task_finished"
              and e["status"] == "failed"]
    assert failed == [] and result.outcome == "found"
    landed = {e["robot"] for e in result.events if e["kind"] == "landed"}
    assert landed == {"uav1", "uav2"}
    assert not [e for e in result.events if e["kind"] == "fault"]


def test_a_uav_over_the_stairwell_lands_on_a_floor_not_down_the_well() -> None:
    """Over building A's stair and lift hall on the third floor (x 60-64 m, open from the
    ground up but for the stair landing) there is no floor to land on: the spot it lands on
    has a slab's top at the floor's level under its middle and its corners."""
    sim = scenario(27, "greedy")
    way = hovering(sim, "uav1", (62.0, 82.0, 8.98))
    spot = way[-1]
    solid = sim.world.solid_array
    tops = solid[np.abs(solid[:, 1, 2] - 7.0) < 0.05]
    for dx, dy in ((0, 0), (-0.3, -0.3), (-0.3, 0.3), (0.3, -0.3), (0.3, 0.3)):
        at = spot[:2] + [dx, dy]
        assert np.any(np.all((at >= tops[:, 0, :2]) & (at <= tops[:, 1, :2]), axis=1))
    assert not np.any(np.all((np.array([62.0, 82.0]) >= tops[:, 0, :2]) &
                             (np.array([62.0, 82.0]) <= tops[:, 1, :2]), axis=1))  # the well


def test_the_finer_search_marks_the_same_free_spots_as_the_spot_by_spot_test() -> None:
    """A grid's free spots, found box by box, are those the spot by spot test finds (boxes
    at exactly the clearance's distance from a spot included)."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        xs = np.arange(1.0, 1.0 + rng.uniform(0.0, 6.0) + 1e-9, LANDING_GRID)
        ys = np.arange(2.0, 2.0 + rng.uniform(0.0, 6.0) + 1e-9, LANDING_GRID)
        lo = rng.uniform(0.0, 9.0, (200, 3))
        lo[:60, 0] = rng.choice(xs, 60) + LANDING_CLEAR  # touching a spot's square
        hi = lo + rng.uniform(0.0, 2.0, (200, 3))
        hi[60:120, 1] = rng.choice(ys, 60) - LANDING_CLEAR
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        spots = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, 1.5)])
        boxes = np.stack([lo, hi], axis=1)
        free = _free_on(boxes, _Grid(xs, ys, 1.5, None), 0.0)
        assert np.array_equal(free, _free(boxes, spots, 0.0))
