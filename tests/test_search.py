"""Searches that find what is there: targets by the walls, at the back of a deep room, and rooms
seen too little searched again."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from conftest import MISSIONS

from astralis_des import Simulation, load_mission
from astralis_des.mission.loader import Mission

ROOM = "A.1.1.2"  # 3.8 x 6.8 m, its door in the south wall
PATTERNS = ("spiral_inward", "spiral_outward", "sweep_horizontal", "sweep_vertical")
SITTING = {"activity": "sitting", "color": "red", "gender": "male", "height": "medium",
           "tied_to_chair": False}


def by_the_walls(mission: Mission, gap: float) -> list[tuple[str, tuple[float, float]]]:
    """Target spots ``gap`` m from each wall (its centre), at the middle of the wall and a
    quarter of the way along it."""
    box = mission.world.rooms[ROOM].box
    (x0, y0, _), (x1, y1, _) = box.lo, box.hi
    spots = []
    for share in (0.5, 0.25):
        xs, ys = x0 + share * (x1 - x0), y0 + share * (y1 - y0)
        spots += [("west", (x0 + gap, ys)), ("east", (x1 - gap, ys)),
                  ("south", (xs, y0 + gap)), ("north", (xs, y1 - gap))]
    return spots


def search_alone(base: Mission, member: dict[str, Any], action: str,
                 spot: tuple[float, float] | None, clutter: bool = False) -> Simulation:
    """One robot searches ROOM with ``action``, the target sitting at ``spot`` (None: in the
    farthest room of the building, out of sight)."""
    target = {"room": ROOM, "position": [spot[0], spot[1], 0.5]} if spot else {"room": "A.3.2.3"}
    sim = Simulation(base.with_changes(
        team=[member], scene={"clutter": clutter}, time_limit=400,
        target={**target, "avatar": SITTING},
        assignment={**base.spec.assignment.model_dump(), "start_at": 390.0}))
    sim.start()
    sim.enqueue(member["id"], action, ROOM)
    sim.advance(380.0)
    return sim


@pytest.mark.parametrize("pattern", PATTERNS)
def test_each_uav_pattern_sees_a_target_by_each_wall(pattern: str) -> None:
    """A still target 0.3 m from a wall (its centre), at the middle and a quarter of each of
    the four walls: every UAV search pattern detects it before its search ends."""
    base = load_mission(MISSIONS / "fig7.yaml")
    missed = []
    for wall, spot in by_the_walls(base, 0.3):
        sim = search_alone(base, {"id": "uav1", "kind": "uav", "start": [70.0, 78.25, 0.0]},
                           pattern, spot)
        if not sim.found.triggered:
            missed.append((wall, spot))
        sim.finish()
    assert missed == []


@pytest.mark.parametrize("action", ["sneak_peek", "observe_corridor"])
def test_the_ugv_sees_a_target_at_the_back_of_a_deep_room(action: str) -> None:
    """The room is 6.8 m deep; the target sits 0.3 m from its back wall, in the middle and a
    quarter of the way across: the UGV's look in from the door detects it. Without a target
    there, its search reports the share of the floor it saw: most of it, not the strips beside
    the door that the door's wall hides (under the 90% a room needs, so it is re-queued)."""
    base = load_mission(MISSIONS / "fig7.yaml")
    box = base.world.rooms[ROOM].box
    for share in (0.5, 0.25):
        spot = (box.lo[0] + share * (box.hi[0] - box.lo[0]), box.hi[1] - 0.3)
        sim = search_alone(base, {"id": "ugv1", "kind": "ugv", "start": [73.0, 78.25, 0.0]},
                           action, spot)
        assert sim.found.triggered, spot
        sim.finish()
    sim = search_alone(base, {"id": "ugv1", "kind": "ugv", "start": [73.0, 78.25, 0.0]},
                       action, None)
    done = [e for e in sim.log.records if e["kind"] == "task_finished"]
    assert len(done) == 1 and done[0]["status"] == "succeeded", done
    assert 0.75 <= done[0]["coverage"] < 0.9
    sim.finish()


def test_a_room_seen_too_little_is_searched_again_by_another_kind() -> None:
    """Segment A.1.1 searched by a UGV and a UAV, the target elsewhere: each room the UGV peeks
    into (seeing under 90% of it) goes back to the pending set with a ``room_undercovered``
    event, and the UAV searches it in a later round, seeing at least 90%; the summary says,
    per room, who searched it and how much each saw."""
    base = load_mission(MISSIONS / "fig7.yaml")
    sim = Simulation(base.with_changes(
        team=[{"id": "ugv1", "kind": "ugv", "start": [73.0, 78.25, 0.0]},
              {"id": "uav1", "kind": "uav", "start": [86.0, 80.0, 0.0]}],
        scene={"clutter": False}, time_limit=1500, target={"room": "A.3.2.3"}))
    result = sim.run()
    assert result.outcome == "not_found"
    low = [e for e in result.events if e["kind"] == "room_undercovered"]
    assert low and all(e["robot"] == "ugv1" and e["requeued"] for e in low)
    assert all(e["coverage"] < 0.9 and e["kinds_left"] == ["uav"] for e in low)
    for event in low:
        room = result.rooms[event["room"]]
        assert room["status"] == "searched" and room["coverage"] >= 0.9
        assert [(s["robot"], s["kind"]) for s in room["searches"]] == [("ugv1", "ugv"),
                                                                       ("uav1", "uav")]
        assert room["searches"][1]["coverage"] >= 0.9
    assert sorted(result.rooms_searched) == ["A.1.1.1", "A.1.1.2", "A.1.1.3"]


@pytest.mark.parametrize("method", ["graph", "map"])
def test_a_uav_flies_over_a_cabinet_under_its_pattern(method: str) -> None:
    """A 2 m cabinet stands under a corner of the UAV's spiral: the UAV climbs over it rather
    than leave that corner out, in either planning method (the kinematic default and the
    physics one), and sees as much of the room as with the room empty."""
    from astralis_des.world.clutter import Clutter, Placed

    base = load_mission(MISSIONS / "fig7.yaml")

    def search(cabinet: bool) -> tuple[Any, np.ndarray, Placed]:
        sim = Simulation(base.with_changes(
            team=[{"id": "uav1", "kind": "uav", "start": [70.0, 78.25, 0.0]}],
            planning={"method": method}, scene={"clutter": False}, time_limit=400,
            target={"room": "A.3.2.3"},
            assignment={**base.spec.assignment.model_dump(), "start_at": 390.0}))
        hi = sim.world.rooms[ROOM].box.hi  # the outer ring's far corner, 1 m off both walls
        item = Placed("cabinet", ROOM, (hi[0] - 1.0, hi[1] - 1.0, 1.0), (1.2, 0.5, 2.0), 0.0)
        if cabinet:
            sim.scene.set_clutter(ROOM, Clutter((item,)))
        sim.start()
        done = sim.enqueue("uav1", "spiral_inward", ROOM)
        sim.advance(380.0)
        assert done.triggered and done.value.ok, done.value.message
        trail = np.array(sim.robots["uav1"].trail_p)
        sim.finish()
        return done.value, trail, item

    empty, _, _ = search(False)
    result, trail, cabinet = search(True)
    assert "out of reach" not in result.message
    assert result.coverage == pytest.approx(empty.coverage, abs=0.03)
    lo = np.subtract(cabinet.center, np.divide(cabinet.size, 2))
    hi = np.add(cabinet.center, np.divide(cabinet.size, 2))
    over = np.all((trail[:, :2] >= lo[:2]) & (trail[:, :2] <= hi[:2]), axis=1)
    assert over.any()  # it flew over the cabinet ...
    assert trail[over, 2].min() >= hi[2] + 0.3  # ... clear of its top by its body's radius


def test_a_uav_leaves_a_point_over_a_cabinet_level_then_down() -> None:
    """A UAV that ended a search over a cabinet (its sensor 2.6 m up) routes on from where it
    is: level until clear of the cabinet, then down, in the planner that checks furniture
    (from its usual height over that spot it would start inside the cabinet)."""
    from astralis_des.world.clutter import Clutter, Placed

    base = load_mission(MISSIONS / "fig7.yaml")
    sim = Simulation(base.with_changes(
        team=[{"id": "uav1", "kind": "uav", "start": [70.0, 78.25, 0.0]}],
        planning={"method": "map"}, scene={"clutter": False}, target={"room": "A.3.2.3"}))
    hi = sim.world.rooms[ROOM].box.hi
    spot = np.array([hi[0] - 1.0, hi[1] - 1.0, 0.0])
    sim.scene.set_clutter(ROOM, Clutter((Placed("cabinet", ROOM, (spot[0], spot[1], 1.0),
                                                (1.2, 0.5, 2.0), 0.0),)))
    robot, nav = sim.robots["uav1"], sim.navigator
    over = nav.usable(robot, spot[None, :] + [0.0, 0.0, robot.height]).points
    assert over is not None and over[0, 2] >= 2.0 + 0.3 + 0.05  # lifted over the cabinet
    goal = np.array([70.0, 78.25, 0.0])  # the corridor
    stuck = nav.route(robot, spot, goal)
    assert stuck.points is None and "start in collision" in stuck.reason
    way = nav.route(robot, spot, goal, at=over[0])
    assert way.points is not None, way.reason
    assert np.allclose(way.points[0], over[0])
    assert way.points[1, 2] == pytest.approx(over[0, 2])  # level first ...
    assert np.linalg.norm(way.points[1, :2] - spot[:2]) > 0.5  # ... past the cabinet
