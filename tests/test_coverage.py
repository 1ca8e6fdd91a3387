"""Coverage paths and the geometric sensor: spacing, coverage shares, detection by sight."""

from __future__ import annotations

import numpy as np
import pytest

from astralis_des.actions import coverage as cov
from astralis_des.actions.common import footprint_spacing
from astralis_des.kernel.robot import Motion, Robot
from astralis_des.kernel.scene import Scene
from astralis_des.sensing import GeometricSensor
from astralis_des.world.catalogue import default_catalogue
from astralis_des.world.geometry import Box
from astralis_des.world.model import World

ROOM = Box((0.0, 0.0, 0.0), (4.0, 7.0, 3.0))


def sensor(world: World, target: tuple[float, float, float] | None = None,
           room: str = "B.1.1.1", messiness: float = 0.0, seed: int = 0) -> GeometricSensor:
    """A sensor in ``world`` furnished at ``messiness``, the target in ``room`` (at ``target``)."""
    scene = Scene(world, dict.fromkeys(world.rooms, messiness), seed, default_catalogue())
    return GeometricSensor(scene, scene.place_target(room, {"activity": "idle"}, target))


def robot(kind: str = "uav", radius: float = 2.0, height: float = 1.5) -> Robot:
    return Robot("r", kind, 1.0, radius, height, np.zeros(3))


def test_spiral_rings_are_spacing_apart_and_inside_the_room() -> None:
    """An inward spiral starts on the outer ring, half a spacing from the walls, ends inside."""
    path = cov.spiral(ROOM, 1.0, inward=True)
    assert path[0] == pytest.approx([0.5, 0.5])
    assert np.all((path >= [0.5, 0.5]) & (path <= [3.5, 6.5]))
    assert np.linalg.norm(path[-1] - [2.0, 3.5]) < np.linalg.norm(path[0] - [2.0, 3.5])


def test_outward_spiral_is_the_inward_one_reversed() -> None:
    """Outward starts where inward ends."""
    inward, outward = cov.spiral(ROOM, 1.2, True), cov.spiral(ROOM, 1.2, False)
    assert np.allclose(inward[::-1], outward)


@pytest.mark.parametrize("axis", [0, 1])
def test_lawnmower_lanes_follow_their_axis(axis: int) -> None:
    """Horizontal sweep lanes run along x, vertical along y, ``spacing`` or less apart."""
    path = cov.lawnmower(ROOM, 1.0, axis)
    lanes = path.reshape(-1, 2, 2)
    assert np.allclose(lanes[:, 0, 1 - axis], lanes[:, 1, 1 - axis])  # each lane is straight
    offsets = np.sort(lanes[:, 0, 1 - axis])
    assert np.all(np.diff(offsets) <= 1.0 + 1e-9)


def test_spacing_follows_the_footprint() -> None:
    """At 1.5 m with a 2 m reach, a target at 0.5 m is seen within sqrt(3) m: spacing 2.77 m."""
    assert footprint_spacing(robot(), 0.2) == pytest.approx(2 * np.sqrt(3) * 0.8)


@pytest.mark.parametrize("pattern", ["spiral_in", "spiral_out", "sweep_x", "sweep_y"])
def test_uav_patterns_cover_at_least_90_percent(world: World, pattern: str) -> None:
    """Each UAV search pattern sees >= 90% of an empty room's floor."""
    room = world.rooms["A.2.1.2"]
    r = robot()
    spacing = footprint_spacing(r, 0.2)
    plane = {
        "spiral_in": lambda: cov.spiral(room.box, spacing, True),
        "spiral_out": lambda: cov.spiral(room.box, spacing, False),
        "sweep_x": lambda: cov.lawnmower(room.box, spacing, 0),
        "sweep_y": lambda: cov.lawnmower(room.box, spacing, 1),
    }[pattern]()
    pts = np.column_stack([plane, np.full(len(plane), room.box.lo[2] + r.height)])
    share = sensor(world).coverage(r, pts, room)
    assert share >= 0.9


def test_a_peek_from_the_door_sees_part_of_the_room_only(world: World) -> None:
    """From the corridor side of the door the walls hide the room's near corners."""
    room = world.rooms["A.1.1.1"]
    eye = np.array([room.door_point("corridor", 0.15)]) + [0, 0, 0.5]
    share = sensor(world).coverage(robot("ugv", 6.0, 0.5), eye, room)
    assert 0.4 < share < 0.95


def test_the_target_is_seen_through_the_door_not_through_the_wall(world: World) -> None:
    """A target in a room is detected from a path past its door, not from behind its wall."""
    room = world.rooms["A.1.1.2"]
    target = (room.center[0], room.center[1], room.box.lo[2] + 0.5)
    seer = sensor(world, target, room.id)
    r = robot("ugv", 6.0, 0.5)
    corridor_y = room.door_point("corridor", 1.0)[1]
    past_door = Motion(np.array([[62.5, corridor_y, 0.5], [79.0, corridor_y, 0.5]]), 1.0)
    seen = seer.first_sighting(r, past_door)
    assert seen is not None
    assert abs(seen.robot_position[0] - room.door.center[0]) < 1.5
    neighbour = world.rooms["A.1.1.1"]
    inside_neighbour = Motion(np.array([neighbour.center, neighbour.door_point("room")]) +
                              [0, 0, 0.5], 1.0)
    assert seer.first_sighting(r, inside_neighbour) is None
