"""The human operator's search action: walk into the room and look around it."""

from __future__ import annotations

from astralis_des.actions.common import (
    ActionGen,
    Context,
    failed,
    plane_to_floor,
    room_of,
    search_path,
)
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import Task
from astralis_des.plugins import ACTIONS
from astralis_des.world import coverage as cov


@ACTIONS.register(("human", "inspect"))
def inspect(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Walk a loop ``inset`` metres (default 1) inside the room's walls, looking around."""
    room = room_of(ctx, task)
    if room is None:
        return failed("inspect needs a room")
    plane = cov.loop(room.box, float(task.param("inset", 1.0)))
    plane = cov.start_near(plane, room.box, room.door_point("room"))  # type: ignore[arg-type]
    return (yield from search_path(ctx, robot, room, plane_to_floor(room, plane), "inspect"))
