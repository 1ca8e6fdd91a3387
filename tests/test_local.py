"""The local layer: robots in physics pass each other and let walkers cross, without contact."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from astralis_des import Simulation, load_mission
from astralis_des.kernel.scene import Mover

ROOT = Path(__file__).resolve().parents[1]
CORRIDOR_Y = 78.25  # centre line of building A's ground-floor corridor


def corridor_mission(team: list[dict]) -> Simulation:
    """Physics, empty rooms, nobody assigned (the search starts an hour later)."""
    base = load_mission(ROOT / "missions" / "fig7.yaml")
    return Simulation(base.with_changes(
        fidelity="physics", team=team, scene={"clutter": False}, time_limit=4000,
        assignment={**base.spec.assignment.model_dump(), "start_at": 3600.0}))


def contacts_between(sim: Simulation, a: str, b: str) -> list[dict]:
    return [e for e in sim.log.records if e["kind"] == "contact"
            and {e.get("robot"), e.get("other")} == {a, b}]


def test_two_uavs_crossing_in_a_corridor_both_arrive_without_contact() -> None:
    """Head-on along the corridor, each keeps right: both arrive, no contact."""
    sim = corridor_mission([
        {"id": "uav1", "kind": "uav", "start": [65.0, CORRIDOR_Y, 0.0]},
        {"id": "uav2", "kind": "uav", "start": [79.0, CORRIDOR_Y, 0.0]},
    ])
    sim.start()
    east = sim.enqueue("uav1", "move", params={"x": 79.0, "y": CORRIDOR_Y})
    west = sim.enqueue("uav2", "move", params={"x": 65.0, "y": CORRIDOR_Y})
    sim.advance(60.0)
    assert east.triggered and west.triggered
    assert east.value.ok and west.value.ok, (east.value.message, west.value.message)
    assert contacts_between(sim, "uav1", "uav2") == []
    assert np.linalg.norm(sim.robots["uav1"].position(sim.env.now)[:2] - [79.0, CORRIDOR_Y]) < 0.3
    sim.finish()


def test_a_walker_crossing_the_ugvs_path_is_let_through() -> None:
    """An avatar walks across the corridor, from a room to the one opposite and back, as the
    UGV drives along it: the UGV waits for it to pass, and nothing touches."""
    sim = corridor_mission([{"id": "ugv1", "kind": "ugv", "start": [65.0, CORRIDOR_Y, 0.0]}])
    crossing = Mover("avatar:crossing", "avatar",
                     np.array([[72.0, 74.5, 0.86], [72.0, 82.0, 0.86], [72.0, 74.5, 0.86]]),
                     0.6, (0.5, 0.5, 1.72), offset=14.55)  # mid-corridor at t = 7 s
    sim.scene.movers.append(crossing)
    sim.cosim._add_movers([crossing])
    sim.start()
    drive = sim.enqueue("ugv1", "move", params={"x": 79.0, "y": CORRIDOR_Y})
    sim.advance(60.0)
    assert drive.triggered and drive.value.ok, drive.value.message
    assert [e for e in sim.log.records if e["kind"] == "contact"] == []
    assert sim.cosim.local.holds > 0  # it did wait for the walker
    sim.finish()
