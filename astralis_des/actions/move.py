"""``move``: every kind goes to a place (a room's centre or door, or a point)."""

from __future__ import annotations

from astralis_des.actions.common import ActionGen, Context, failed, go_to, room_of, stand_off
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import Task
from astralis_des.kinds import KINDS
from astralis_des.plugins import ACTIONS


def move(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Params: ``point`` = ``center`` (default) or ``door`` with a room; or ``x``, ``y``, ``z``;
    ``look`` = 1: watch for the target on the way (teleoperation does)."""
    room = room_of(ctx, task)
    if room is not None:
        ctx.sensor.scene.clutter(room.id)  # its furniture is there before the robot is
        where = task.param("point", "center")
        goal = room.center if where == "center" else room.door_point("corridor",
                                                                     stand_off(robot))
    elif all(k in dict(task.params) for k in ("x", "y")):
        goal = (float(task.param("x", 0)), float(task.param("y", 0)), float(task.param("z", 0)))
    else:
        return failed("move needs a room or x and y")
    return (yield from go_to(ctx, robot, goal, sense=bool(task.param("look", 0))))


for _kind in KINDS:
    ACTIONS.register((_kind, "move"))(move)
