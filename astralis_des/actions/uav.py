"""UAV actions of Table I: hover, inward and outward spiral search, vertical and horizontal
sweep."""

from __future__ import annotations

from astralis_des.actions.common import (
    ActionGen,
    Context,
    dwell,
    failed,
    footprint_spacing,
    plane_to_floor,
    result,
    room_of,
    search_path,
    take_off,
)
from astralis_des.actions.landing import land
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import Task, TaskStatus
from astralis_des.plugins import ACTIONS
from astralis_des.world import coverage as cov

OVERLAP = 0.2  # share of the footprint that neighbouring passes see twice
WALL_MARGIN = 1.0  # m: the outermost pass runs at most this far inside the walls, so that the
# camera, which looks ahead and down, sees the strip along each wall


@ACTIONS.register(("uav", "hover"))
def hover(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Hold position and look around for ``duration`` seconds (default 10)."""
    seconds = float(task.param("duration", 10.0))
    yield from dwell(ctx, robot, seconds)
    return result(TaskStatus.SUCCEEDED, f"hovered {seconds:g} s")


@ACTIONS.register(("uav", "take_off"))
def take_off_action(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Climb straight up from the ground to the flight height (a UAV on the ground also
    does this by itself before any other action)."""
    flying = robot.airborne
    distance = yield from take_off(ctx, robot)
    return result(TaskStatus.SUCCEEDED, "already flying" if flying else "took off",
                  distance=distance)


@ACTIONS.register(("uav", "land"))
def land_action(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Come straight down onto the floor below and stay there (the next action takes off
    again). UAVs land by themselves when the mission ends."""
    flying = robot.airborne
    distance = yield from land(ctx, robot)
    return result(TaskStatus.SUCCEEDED, "landed" if flying else "already on the ground",
                  distance=distance)


def _pattern(name: str, inward: bool | None = None, axis: int | None = None):  # type: ignore[no-untyped-def]
    def action(ctx: Context, robot: Robot, task: Task) -> ActionGen:
        room = room_of(ctx, task)
        if room is None:
            return failed(f"{name} needs a room")
        spacing = float(task.param("spacing", footprint_spacing(robot, OVERLAP)))
        if axis is None:
            plane = cov.spiral(room.box, spacing, inward=bool(inward), margin=WALL_MARGIN)
        else:
            plane = cov.lawnmower(room.box, spacing, axis, margin=WALL_MARGIN)
        entry = room.door_point("room")
        plane = cov.start_near(plane, room.box, entry)  # type: ignore[arg-type]
        return (yield from search_path(ctx, robot, room, plane_to_floor(room, plane), name))

    action.__name__ = name
    action.__doc__ = f"{name.replace('_', ' ')} over the room, passes ``spacing`` apart."
    return action


for _name, _inward, _axis in (
    ("spiral_inward", True, None), ("spiral_outward", False, None),
    ("sweep_horizontal", None, 0), ("sweep_vertical", None, 1),
):
    ACTIONS.register(("uav", _name))(_pattern(_name, _inward, _axis))
