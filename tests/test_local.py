"""The local layer: robots in physics pass each other and let walkers cross, without contact."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from astralis_des import Simulation, load_mission
from astralis_des.world.scene import Mover

ROOT = Path(__file__).resolve().parents[1]
CORRIDOR_Y = 78.25  # centre line of building A's ground-floor corridor
LOW = 1.5  # m: a UAV flown at head height, which must avoid walkers (by default it flies over
# them, at 1.975 m)


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
    sim.cosim.bodies.add_movers([walker])


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
    sim = corridor_mission([{"id": "uav1", "kind": "uav", "start": [64.5, uav_y, 0.0],
                             "height": LOW}])
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
        {"id": "uav1", "kind": "uav", "start": [x + 2.0, CORRIDOR_Y, 0.0], "height": LOW},
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



def test_a_walker_that_stepped_round_a_standing_ugv_is_not_held_by_it() -> None:
    """Scenario 8 (naive) of the physics outcome study: a person walking west along the
    corridor meets the UGV standing idle at a door, 0.25 m off its path, with no room to make
    way. The step round it must take the person past the lane's edge: it used to put the path
    exactly on it (0.79999 m off, the lane 0.8 m), so the person held for 15 s, until its move
    failed as stuck."""
    from astralis_des.kinds import KIND_DEFAULTS
    from astralis_des.physics.courses import on_route
    from astralis_des.physics.local import Body, LocalLayer

    # the person's path ahead and the UGV as the local layer saw them at t = 22 s
    path = np.column_stack([76.11828760509543 - 0.19963966349279 * np.arange(16),
                            78.43223407838225 + 0.01200019835202 * np.arange(16)])
    ugv = Body("ugv1", "ugv", np.array([74.12991336611312, 78.66263168889651]), np.zeros(2),
               (0.0, 0.65), KIND_DEFAULTS["ugv"].passes_by, 10_000, half_width=0.4)
    forward = np.array([-0.9981983174639202, 0.06000099176012755])
    right = np.array([forward[1], -forward[0]])
    shift = np.array([-0.04135945353275388, -0.688070908772107])  # its step aside then
    lane = KIND_DEFAULTS["human"].passes_by + ugv.half_width + 0.15
    assert on_route(path + shift, ugv.xy, ugv.velocity)[1] < lane  # on the edge: held
    for _ in range(2):  # decide, step as decided, decide again
        me = Body("human1", "human", path[0] + shift, forward * 1.2, (0.0, 1.75),
                  KIND_DEFAULTS["human"].passes_by, 2, offset=shift)
        hold, shift, aside, blockers = LocalLayer._decide(
            None, me, [ugv], forward, right, 1.2, path + shift)  # type: ignore[arg-type]
        assert aside
    assert on_route(path + shift, ugv.xy, ugv.velocity)[1] > lane + 0.04  # clear of the edge
    assert not hold and blockers == []



def test_a_uav_coming_down_from_a_lifted_point_does_not_come_down_onto_a_walker() -> None:
    """Scenario 6 (naive) of the physics outcome study: a UAV hovering at 2.2 m (where it made
    way, over furniture) sets off on a path that comes down to 1.5 m, towards an avatar
    walking at it. Its band for the climb rule is the lowest its course comes to on the path
    ahead, so the walker counts, and each look keeps it over the walker's head as its course
    comes down; judged at its hover height alone, the walker passed below it, the UAV came
    down onto it and was tipped over."""
    from dataclasses import replace

    from astralis_des.kinds import KIND_DEFAULTS
    from astralis_des.physics.climb import Climber
    from astralis_des.physics.local import Body, _lowest

    ahead = np.column_stack([np.full(16, 65.1), np.linspace(71.3, 68.3, 16),
                             np.linspace(2.2, 1.5, 16)])
    uav = Body("uav2", "uav", np.array([65.1, 71.3]), np.array([0.0, -0.5]), (2.0, 2.2),
               KIND_DEFAULTS["uav"].passes_by, 1, base_z=(2.1, 2.3))
    walker = Body("avatar", "avatar", np.array([65.1, 72.7]), np.array([0.0, -1.0]),
                  (0.0, 1.72), 0.25, 10_000)
    climber = Climber(lambda robot, points: np.ones(len(points), dtype=bool))
    paths = {"avatar": np.column_stack([np.full(16, 65.1), 72.7 - np.linspace(0.0, 3.0, 16)])}
    # lower on its way, each look: at 2.0 m its band is under the walker's head and margin
    for course in (2.2, 2.0, 1.8, 1.5):
        here = replace(uav, base_z=(course - 0.1, course + 0.1))
        need, _ = climber.need(here, [walker], uav.velocity, ahead[:, :2], ahead[:, :2], True,
                               paths, _lowest(here, ahead))
        assert course - 0.1 + need >= walker.z[1] + 0.3 - 1e-9  # over the walker's head
    assert climber.need(uav, [walker], uav.velocity, ahead[:, :2], ahead[:, :2], True,
                        paths)[0] == 0.0  # judged at its hover height alone: the crash


def test_a_uav_setting_off_meets_the_walkers_where_they_are_now() -> None:
    """Scenario 6 (mixed) of the physics outcome study: while no robot moved near it, a
    patrolling avatar's body was left where it last was, on the spot a UAV waited at; its
    script walked on. When the UAV set off, the stale body was still in it: a contact, and
    the UAV tipped over. A robot setting off now puts every mover where it is."""
    sim = corridor_mission([{"id": "uav1", "kind": "uav", "start": [70.0, CORRIDOR_Y, 0.0]}])
    add_walker(sim, [(75.0, CORRIDOR_Y), (79.0, CORRIDOR_Y)])  # 5 m and more away
    sim.start()
    hop = sim.enqueue("uav1", "move", params={"x": 70.5, "y": CORRIDOR_Y})  # then it waits
    sim.advance(10.0)
    assert hop.triggered and hop.value.ok
    _, body = sim.cosim.movers[-1]
    here = sim.cosim.drivers["uav1"].position()
    sim.cosim.client.call("resetBasePositionAndOrientation", body,  # left behind on its spot
                          [here[0] + 0.2, here[1], 0.86], [0.0, 0.0, 0.0, 1.0])
    done = sim.enqueue("uav1", "move", params={"x": 66.0, "y": CORRIDOR_Y})
    sim.advance(20.0)
    assert done.triggered and done.value.ok, done.value.message
    assert [e for e in sim.log.records if e["kind"] in ("contact", "fault")] == []
    sim.finish()


def test_a_husky_standing_by_the_stairs_makes_way_along_the_corridor() -> None:
    """The fidelity benchmark's scenario 18 (naive): the Husky stood idle on the second
    floor's corridor 2 m from the stairs, on the person's way up. The corridor (2.5 m, 2.3 m
    where it meets the stair hall) leaves no spot 1 to 2 m aside that clears the person's
    path by both bodies and a margin (1.17 m), so it never made way and the person failed
    'stuck'. It now goes along the corridor, away from the person, past the stairs; the
    person goes up without touching it."""
    sim = corridor_mission([{"id": "human1", "kind": "human", "start": [70.0, CORRIDOR_Y, 3.5]},
                            {"id": "ugv1", "kind": "ugv", "start": [65.13, CORRIDOR_Y, 3.5]}])
    sim.start()
    done = sim.enqueue("human1", "move", room="A.3.1.3")
    sim.advance(60.0)
    assert done.triggered and done.value.status.value == "succeeded"
    (made,) = [e for e in sim.log.records if e["kind"] == "make_way"]
    assert (made["robot"], made["for_robot"]) == ("ugv1", "human1")
    spot = np.array(made["to"])
    assert spot[0] < 63.2 - 1.17 and abs(spot[1] - CORRIDOR_Y) < 0.01  # past the stairs
    path = np.concatenate([p for _, p in sim.robots["human1"].plans])
    assert np.linalg.norm(path[:, :2] - spot[:2], axis=1).min() >= 1.17
    assert not contacts_between(sim, "human1", "ugv1")
