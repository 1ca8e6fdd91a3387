"""UGV actions of Table I: sneak peek into a room, observe along a corridor."""

from __future__ import annotations

import math

import numpy as np

from astralis_des.actions import ACTIONS
from astralis_des.actions.common import (
    ActionGen,
    Context,
    dwell,
    failed,
    result,
    room_of,
    route,
    traverse,
)
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import Task, TaskStatus

SNEAK_OFFSET = 0.5  # m in front of the wall's face: where the UGV's body clears the jambs


@ACTIONS.register(("ugv", "sneak_peek"))
def sneak_peek(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Drive to the room's door, look in from the threshold for ``dwell`` seconds (default 5)."""
    room = room_of(ctx, task)
    if room is None:
        return failed("sneak_peek needs a room")
    way = route(ctx, robot, room.door_point("corridor", offset=SNEAK_OFFSET))
    if way.points is None:
        return failed(way.reason)
    distance = yield from traverse(ctx, robot, way.points, sense=False)
    here = robot.position(ctx.env.now)
    into = math.atan2(room.center[1] - here[1], room.center[0] - here[0])
    yield ctx.cosim.face(robot, into)  # turn the camera into the room
    coverage = ctx.sensor.coverage(robot, here[None, :], room)
    yield from dwell(ctx, robot, float(task.param("dwell", 5.0)))
    return result(TaskStatus.SUCCEEDED, f"sneak peek saw {coverage:.0%} of {room.id}",
                  distance=distance, coverage=coverage)


@ACTIONS.register(("ugv", "observe_corridor"))
def observe_corridor(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Drive the corridor past the doors of the room's segment, scanning into the rooms."""
    room = room_of(ctx, task)
    if room is None:
        return failed("observe_corridor needs a room")
    corridor = ctx.world.spaces[room.corridor].box
    doors = [ctx.world.rooms[r].door.center[0] for r in ctx.world.segments[room.segment].rooms]
    margin = float(task.param("margin", 1.5))
    x0 = max(min(doors) - margin, corridor.lo[0] + 0.3)
    x1 = min(max(doors) + margin, corridor.hi[0] - 0.3)
    y = (corridor.lo[1] + corridor.hi[1]) / 2
    z = corridor.lo[2]
    ends = [np.array([x0, y, z]), np.array([x1, y, z])]
    here = robot.position(ctx.env.now)
    if abs(here[0] - x1) < abs(here[0] - x0):
        ends.reverse()
    way = route(ctx, robot, tuple(ends[0]))
    if way.points is None:
        return failed(way.reason)
    distance = yield from traverse(ctx, robot, way.points, sense=False)
    drive = np.array(ends) + np.array([0.0, 0.0, robot.height])
    coverage = ctx.sensor.coverage(robot, drive, room)
    distance += yield from traverse(ctx, robot, drive, sense=True)
    return result(TaskStatus.SUCCEEDED, f"observed the corridor, saw {coverage:.0%} of {room.id}",
                  distance=distance, coverage=coverage)
