"""The local layer: robots in physics pass each other and let walkers cross, without contact."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

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


def add_walker(sim: Simulation, ends: list[tuple[float, float]], offset: float = 0.0) -> None:
    """An avatar pacing between two points of the ground floor at 0.6 m/s."""
    loop = np.array([[*ends[0], 0.86], [*ends[1], 0.86], [*ends[0], 0.86]])
    walker = Mover("avatar:walker", "avatar", loop, 0.6, (0.5, 0.5, 1.72), offset=offset)
    sim.scene.movers.append(walker)
    sim.cosim._add_movers([walker])


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
    add_walker(sim, [(72.0, 74.5), (72.0, 82.0)], offset=14.55)  # mid-corridor at t = 7 s
    sim.start()
    drive = sim.enqueue("ugv1", "move", params={"x": 79.0, "y": CORRIDOR_Y})
    sim.advance(60.0)
    assert drive.triggered and drive.value.ok, drive.value.message
    assert [e for e in sim.log.records if e["kind"] == "contact"] == []
    assert sim.cosim.local.holds > 0  # it did wait for the walker
    sim.finish()


def _flight_past_avatar(uav_y: float, avatar_y: float) -> Simulation:
    """A UAV flies east along the corridor at ``uav_y`` while an avatar walks west at
    ``avatar_y``, 1.05 m to its left, over the same stretch (x 68.4 to 71.6)."""
    sim = corridor_mission([{"id": "uav1", "kind": "uav", "start": [64.5, uav_y, 0.0]}])
    add_walker(sim, [(71.6, avatar_y), (68.4, avatar_y)])
    sim.start()
    done = sim.enqueue("uav1", "move", params={"x": 76.0, "y": uav_y})
    sim.advance(30.0)
    assert done.triggered and done.value.ok, done.value.message
    return sim


def test_keep_right_ignores_an_avatar_behind_a_wall() -> None:
    """The avatar walks in the room beside the corridor (room A.1.1.2, 0.35 m beyond the
    wall): the UAV flies straight on, never shifted. The same avatar the same distance away
    in the corridor makes it keep right."""
    behind = _flight_past_avatar(78.9, 79.95)
    assert behind.cosim.local.shifts == 0
    ys = np.array(behind.robots["uav1"].trail_p)[:, 1]
    assert np.abs(ys - 78.9).max() < 0.1
    behind.finish()
    in_sight = _flight_past_avatar(77.95, 79.0)
    assert in_sight.cosim.local.shifts > 0
    assert np.array(in_sight.robots["uav1"].trail_p)[:, 1].min() < 77.95 - 0.2
    in_sight.finish()


DOORS = [(70.0, 79.5), (66.0, 79.5), (74.0, 79.5), (66.0, 77.0), (70.0, 77.0), (74.0, 77.0)]


@pytest.mark.parametrize("door", DOORS, ids=lambda d: f"door_{d[0]:g}_{d[1]:g}")
def test_a_uav_and_a_walker_cross_a_doorway_head_on_without_touching(
        door: tuple[float, float]) -> None:
    """In every doorway of the ground floor: the UAV flies from the corridor into the room
    as the operator walks out of it into the corridor. Both get there, and the UAV touches
    neither the door's jambs nor the operator."""
    x, y = door
    inward = 1.0 if y > CORRIDOR_Y else -1.0
    room = (x, y + inward * 3.4)
    sim = corridor_mission([
        {"id": "uav1", "kind": "uav", "start": [x + 2.0, CORRIDOR_Y, 0.0]},
        {"id": "op1", "kind": "human", "start": [x - 0.8, room[1], 0.0]},
    ])
    sim.start()
    fly = sim.enqueue("uav1", "move", params={"x": room[0], "y": room[1]})
    walk = sim.enqueue("op1", "move", params={"x": x - 2.0, "y": CORRIDOR_Y})
    sim.advance(60.0)
    assert fly.triggered and walk.triggered
    assert fly.value.ok and walk.value.ok, (fly.value.message, walk.value.message)
    assert [e for e in sim.log.records if e["kind"] == "contact"
            and "uav1" in (e.get("robot"), e.get("other"))] == []
    sim.finish()


@pytest.mark.parametrize("offset", [0.0, 1.0, 2.0, 3.0, 4.0, 5.0])
def test_a_uav_leaving_a_room_waits_for_a_walker_passing_the_door(offset: float) -> None:
    """The UAV flies out of room A.1.2.2 through its door into the corridor as an avatar
    paces along the corridor past that door (at one of six timings): it waits in the room or
    the doorway for the walker to pass, or climbs over it, and never touches it on its way
    (one that walked into it tipped it over). Once there, it stands idle: a walker may brush
    it then, and it does not fall (an idle UAV is held still)."""
    sim = corridor_mission([{"id": "uav1", "kind": "uav", "start": [74.0, 74.5, 0.0]}])
    add_walker(sim, [(78.0, CORRIDOR_Y - 0.4), (67.0, CORRIDOR_Y - 0.4)], offset=offset)
    sim.start()
    done = sim.enqueue("uav1", "move", params={"x": 69.0, "y": CORRIDOR_Y})
    sim.advance(40.0)
    assert done.triggered and done.value.ok, done.value.message
    assert not sim.robots["uav1"].faulted
    arrived = next(e["t"] for e in sim.log.records if e["kind"] == "task_finished")
    assert [e for e in sim.log.records if e["kind"] == "contact" and e["t"] < arrived] == []
    sim.finish()
