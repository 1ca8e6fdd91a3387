"""The vehicle lift: the UGV rides it between floors and drives on the floor it reports; UAVs
change floors at the stairwell's far end, clear of it."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from astralis_des import Simulation, load_mission
from astralis_des.physics.husky import REST_Z

ROOT = Path(__file__).resolve().parents[1]
CORRIDOR_Y = 78.25


def lone(kind: str, start: list[float]) -> Simulation:
    """One robot in building A, physics, empty rooms, nobody assigned."""
    base = load_mission(ROOT / "missions" / "fig7.yaml")
    return Simulation(base.with_changes(
        fidelity="physics", team=[{"id": "r1", "kind": kind, "start": start}],
        scene={"clutter": False}, time_limit=4000,
        assignment={**base.spec.assignment.model_dump(), "start_at": 3600.0}))


def test_the_ugv_rides_the_lift_to_floor_3_and_drives_on_it() -> None:
    """From the ground floor's corridor to a third-floor door: the move succeeds, and at
    every pose sample the body stands on the floor the UGV reports (within 5 cm), at its
    two lift rides too; it ends on floor 3."""
    sim = lone("ugv", [70.0, CORRIDOR_Y, 0.0])
    driver = sim.cosim.drivers["r1"]
    samples: list[tuple[float, float]] = []
    tick = driver.tick

    def watched(t: float) -> str | None:
        out = tick(t)
        body_floor = driver.husky.pose()[2] - REST_Z
        reported = driver.position()[2] - sim.robots["r1"].height
        samples.append((body_floor, reported))
        return out

    driver.tick = watched
    sim.start()
    done = sim.enqueue("r1", "move", "A.3.1.2", {"point": "door"})
    sim.advance(200.0)
    assert done.triggered and done.value.ok, done.value.message
    floors, reported = np.array(samples).T
    assert np.abs(floors - reported).max() < 0.05
    assert floors.min() > -0.05 and floors.max() > 6.95  # ground floor to floor 3 (7 m)
    here = sim.robots["r1"].position(sim.env.now)
    assert abs(here[2] - (7.0 + sim.robots["r1"].height)) < 0.05
    assert sim.world.rooms["A.3.1.2"].door.center[2] == 7.0
    assert not [e for e in sim.log.records if e["kind"] in ("fault", "contact")]
    lift = sim.cosim.lifts[0]
    assert lift.z == pytest.approx(7.0) and lift.rider is None  # left at floor 3, free again
    sim.finish()


def test_the_ugv_comes_back_down_on_the_lift() -> None:
    """Up to floor 2 and back to the ground floor's corridor: both legs succeed."""
    sim = lone("ugv", [70.0, CORRIDOR_Y, 0.0])
    sim.start()
    up = sim.enqueue("r1", "move", "A.2.2.1", {"point": "door"})
    down = sim.enqueue("r1", "move", params={"x": 72.0, "y": CORRIDOR_Y, "z": 0.0})
    sim.advance(300.0)
    assert up.value.ok and down.value.ok, (up.value.message, down.value.message)
    assert abs(sim.robots["r1"].position(sim.env.now)[2] - sim.robots["r1"].height) < 0.05
    sim.finish()


def test_uavs_change_floors_in_the_well_clear_of_the_lift_column() -> None:
    """A UAV's route between floors rises where the lift's column is not."""
    world = load_mission(ROOT / "missions" / "fig7.yaml").world
    way = world.router.route(np.array([70.0, CORRIDOR_Y, 0.0]),
                             np.array(world.rooms["A.3.1.2"].door_point("corridor")), "uav")
    assert way is not None
    rising = [(a, b) for a, b in itertools.pairwise(way) if abs(b[2] - a[2]) > 0.3]
    assert rising
    sim = lone("uav", [70.0, CORRIDOR_Y, 0.0])
    lift = sim.cosim.lifts[0]
    for a, _ in rising:
        assert not lift.contains(a, 0.5), a
    sim.finish()
