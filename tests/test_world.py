"""The default urban world: buildings, floors, segments, rooms, and routes through them."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from astralis_des.errors import InputError
from astralis_des.world.build import load_world
from astralis_des.world.model import World
from astralis_des.world.routing import Router


def test_site_is_about_38000_square_metres(world: World) -> None:
    """The outdoor site matches the paper's estimate of 38,000 m^2 within 5%."""
    assert world.area == pytest.approx(38_000, rel=0.05)
    assert set(world.buildings) == {"A", "B"}


def test_building_a_has_3_storeys_6_segments_of_3_rooms(world: World) -> None:
    """Building A: 3 storeys, 6 segments, 18 rooms with ids building.floor.segment.room."""
    segments = [s for s in world.segments.values() if s.building == "A"]
    assert world.buildings["A"].floors == 3
    assert len(segments) == 6
    assert all(len(s.rooms) == 3 for s in segments)
    rooms = sorted(r for r in world.rooms if r.startswith("A."))
    expected = sorted(f"A.{f}.{s}.{r}" for f in (1, 2, 3) for s in (1, 2) for r in (1, 2, 3))
    assert rooms == expected
    assert world.segment_order("A") == ["A.1.1", "A.1.2", "A.2.1", "A.2.2", "A.3.1", "A.3.2"]


def test_rooms_are_about_7_by_4_metres(world: World) -> None:
    """Every room's clear interior is 4 m x 7 m less the walls, on its floor's level."""
    for room in world.rooms.values():
        sx, sy, _ = room.box.size
        assert sorted((sx, sy)) == pytest.approx([3.8, 6.8])
        assert room.box.lo[2] == pytest.approx((room.floor - 1) * 3.5)


def test_building_b_is_smaller(world: World) -> None:
    """Building B has fewer rooms and floors than A."""
    b_rooms = [r for r in world.rooms if r.startswith("B.")]
    assert len(b_rooms) == 6
    assert world.buildings["B"].floors < world.buildings["A"].floors


def test_walls_block_sight_and_doors_let_it_through(world: World) -> None:
    """A line from a room's centre to its neighbour's is blocked; through the door it is not."""
    a, b = world.rooms["A.1.1.1"], world.rooms["A.1.1.2"]
    eye = np.array([a.center]) + [0, 0, 1.0]
    assert not world.line_of_sight(eye, np.array([b.center]) + [0, 0, 1.0])[0]
    corridor = np.array([a.door_point("corridor", 1.0)]) + [0, 0, 1.0]
    assert world.line_of_sight(eye, corridor)[0]


@pytest.mark.parametrize("kind", ["uav", "ugv", "human"])
def test_routes_never_cross_a_wall(world: World, kind: str) -> None:
    """Every leg of every route between rooms, and from outdoors, has a clear line of sight."""
    starts = [(20.0, 20.0, 0.0), world.rooms["A.1.1.1"].center, world.rooms["B.1.1.2"].center]
    goals = [world.rooms[r].center for r in ("A.1.2.3", "A.2.1.1", "A.3.2.2", "B.2.1.3")]
    for start, goal in itertools.product(starts, goals):
        route = world.router.route(start, goal, kind)
        assert route is not None
        legs = route + [0.0, 0.0, 1.0]  # at sensor height, above the floor slabs
        assert world.line_of_sight(legs[:-1], legs[1:]).all(), (start, goal)
        assert np.allclose(route[0], start) and np.allclose(route[-1], goal)


def test_routes_upstairs_climb_the_stairwell(world: World) -> None:
    """Walking to the third floor climbs two switchback flights (each a run of twice its
    3.5 m rise, out and back); a UAV rises straight up at the stairwell's north end; the UGV
    rides the lift straight up in its shaft. The three never share the way between floors."""
    goal = world.rooms["A.3.1.2"].center
    routes = {kind: world.router.route((20.0, 20.0, 0.0), goal, kind)
              for kind in ("human", "uav", "ugv")}
    assert all(r is not None for r in routes.values())
    for route in routes.values():
        assert {0.0, 3.5, 7.0} <= set(np.round(route[:, 2], 3))  # type: ignore[index]

    def climbing(route: np.ndarray) -> np.ndarray:
        legs = np.diff(route, axis=0)
        return np.flatnonzero(np.abs(legs[:, 2]) > 1e-9)

    walk, fly, drive = routes["human"], routes["uav"], routes["ugv"]
    flights = np.diff(walk, axis=0)[climbing(walk)]  # type: ignore[arg-type]
    assert len(flights) == 4
    assert np.allclose(np.abs(flights[:, 1]), 3.5) and np.allclose(flights[:, 2], 1.75)
    for route in (fly, drive):  # straight up: no horizontal motion while climbing
        legs = np.diff(route, axis=0)[climbing(route)]  # type: ignore[arg-type]
        assert len(legs) == 2 and np.allclose(legs[:, :2], 0.0)
    shaft = world.buildings["A"].lift
    assert shaft is not None
    assert all(shaft.contains(drive[i]) for i in climbing(drive))  # type: ignore[index]
    uav_xy = fly[climbing(fly)][:, :2]  # type: ignore[index]
    assert not any(shaft.contains((*xy, 1.0), 0.5) for xy in uav_xy)
    walker_xy = walk[climbing(walk)][:, :2]  # type: ignore[index]
    assert np.linalg.norm(uav_xy[:, None] - walker_xy[None], axis=2).min() > 2.0


def test_a_kept_route_is_keyed_on_both_ends_and_the_kind(world: World) -> None:
    """Asked again, a route is the kept one (read-only); a moved start, another goal or another
    kind is routed anew, as a fresh router routes it."""
    start, goal = (20.0, 20.0, 0.0), world.rooms["A.3.1.2"].center
    first = world.router.route(start, goal, "human")
    assert first is not None and world.router.route(start, goal, "human") is first
    assert not first.flags.writeable
    fresh = Router(world)
    for ends, kind in ((((21.0, 20.0, 0.0), goal), "human"), ((start, goal), "uav"),
                       ((start, world.rooms["A.1.1.1"].center), "human")):
        again = world.router.route(*ends, kind)
        assert again is not None and not np.array_equal(again, first)
        assert np.array_equal(again, fresh._route(np.asarray(ends[0], dtype=float),
                                                  np.asarray(ends[1], dtype=float), kind))
    room = world.rooms["A.1.1.1"]
    assert [world.router.place_of(p) for p in (start, room.center, start)] == [
        "outdoor", "A.1.1.1", "outdoor"]
    with pytest.raises(InputError):  # refused each time it is asked, never kept
        world.router.place_of((-5.0, 10.0, 0.0))
    with pytest.raises(InputError):
        world.router.place_of((-5.0, 10.0, 0.0))


def test_points_inside_walls_or_outside_the_site_are_refused(world: World) -> None:
    """A start inside a building's wall or off the site is an InputError, not a wrong route."""
    with pytest.raises(InputError, match="outside the world"):
        world.router.place_of((-5.0, 10.0, 0.0))
    with pytest.raises(InputError, match="inside a building or obstacle"):
        world.router.place_of((78.0, 84.0, 1.0))  # the closed space beside the lobby


def test_a_world_file_edited_between_two_loads_is_read_anew(tmp_path: Path) -> None:
    # found by the fuzzer: worlds were cached by path, so a notebook or a server that loaded a
    # world, then its edited file, kept the first one (a mission on it named the old buildings)
    path = tmp_path / "w.yaml"
    body = "name: w\nsite: {size: [60, 40]}\nbuildings:\n  - {id: %s, origin: [10, 10], " \
           "floors: 1, segments: [{side: north, rooms: 1}]}\n"
    path.write_text(body % "A", encoding="utf-8")
    assert list(load_world(path).buildings) == ["A"]
    path.write_text(body % "HQ", encoding="utf-8")
    assert list(load_world(path).buildings) == ["HQ"]
    assert load_world(path) is load_world(path)  # the same file is built once


def test_a_world_of_too_many_rooms_is_refused_at_once(tmp_path: Path) -> None:
    # found by the fuzzer: 388 floors of 516 rooms (200,232 rooms) were built before the site
    # check refused them: 42 s to a one-line error
    path = tmp_path / "w.yaml"
    path.write_text("name: w\nsite: {size: [3500, 4700]}\nbuildings:\n  - {id: t, origin: "
                    "[1, 1], floors: 388, segments: [{side: south, rooms: 516}]}\n",
                    encoding="utf-8")
    with pytest.raises(InputError, match=r"w.yaml:\d+: buildings\[0\]: building t has "
                                         r"200,208 rooms; a world holds at most 10,000"):
        load_world(path)


def test_buildings_under_the_room_bound_each_are_refused_together(tmp_path: Path) -> None:
    path = tmp_path / "w.yaml"
    building = "{id: %s, origin: [%d, 1], floors: 10, segments: [{side: south, rooms: 600}]}"
    path.write_text("name: w\nsite: {size: [9000, 100]}\nbuildings:\n" + "".join(
        f"  - {building % (b, 1 + 3000 * k)}\n" for k, b in enumerate("ab")), encoding="utf-8")
    with pytest.raises(InputError, match=r"w.yaml:\d+: buildings: the buildings have 12,000 "
                                         r"rooms; a world holds at most 10,000"):
        load_world(path)
