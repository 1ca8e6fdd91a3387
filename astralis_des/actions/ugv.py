"""UGV actions of Table I: sneak peek into a room, observe along a corridor."""

from __future__ import annotations

import math
from collections.abc import Generator
from typing import Any

import numpy as np
import simpy
from pydantic import Field

from astralis_des.action_spec import ActionParams, Number, Verb
from astralis_des.actions.common import (
    ActionGen,
    Context,
    MotionFailed,
    dwell,
    failed,
    result,
    room_of,
    route,
    stand_off,
    traverse,
)
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import Task, TaskStatus
from astralis_des.plugins import action
from astralis_des.world.model import Room

SNEAK_OFFSET = 0.5  # m in front of the wall's face at least (more for a body that must turn)


class PeekParams(ActionParams):
    dwell: Number = Field(5.0, ge=0.0, le=600.0, description="s looking in from the door")


class CorridorParams(ActionParams):
    dwell: Number = Field(1.0, ge=0.0, le=600.0,
                          description="s looking from each spot of the corridor")


@action("sneak_peek", ("ugv",), params=PeekParams, search=True, seconds_per_m2=0.238,
        table4=((False, False),), verbs=(Verb("sneak-peek", "look into a room from its door"),))
def sneak_peek(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Drive to the room's door, look in from the threshold for ``dwell`` seconds."""
    room = room_of(ctx, task)
    if room is None:
        return failed("sneak_peek needs a room")
    seconds = PeekParams.model_validate(dict(task.params)).dwell
    outcome = yield from _peek(ctx, robot, room, seconds)
    if isinstance(outcome, str):
        return failed(outcome)
    distance, coverage = outcome
    return result(TaskStatus.SUCCEEDED, f"sneak peek saw {coverage:.0%} of {room.id}",
                  distance=distance, coverage=coverage)


@action("observe_corridor", ("ugv",), params=CorridorParams, search=True,
        seconds_per_m2=0.753, table4=((True, False), (False, True), (True, True)),
        verbs=(Verb("observe", "watch a room's corridor"),))
def observe_corridor(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Drive along the corridor of the room's segment and look into each of its rooms from
    the door (``dwell`` seconds each), nearest door first: the camera looks ahead,
    so the robot turns to each door. The coverage is that of the task's room."""
    room = room_of(ctx, task)
    if room is None:
        return failed("observe_corridor needs a room")
    here = robot.position(ctx.env.now)
    rooms = sorted((ctx.world.rooms[r] for r in ctx.world.segments[room.segment].rooms),
                   key=lambda r: r.door.center[0])
    first, last = rooms[0].door.center[0], rooms[-1].door.center[0]
    if abs(here[0] - last) < abs(here[0] - first):
        rooms.reverse()
    distance, coverage = 0.0, 0.0
    seconds = CorridorParams.model_validate(dict(task.params)).dwell
    for other in rooms:
        outcome = yield from _peek(ctx, robot, other, seconds)
        if isinstance(outcome, str):
            return failed(outcome)
        distance += outcome[0]
        if other.id == room.id:
            coverage = outcome[1]
    return result(TaskStatus.SUCCEEDED, f"observed the corridor, saw {coverage:.0%} of {room.id}",
                  distance=distance, coverage=coverage)


def _peek(ctx: Context, robot: Robot, room: Room,
          seconds: float) -> Generator[simpy.Event, Any, tuple[float, float] | str]:
    """Drive to ``room``'s door, looking ahead; turn into the room and look for ``seconds``.
    Returns the distance driven and the share of the room seen, or why it failed."""
    way = route(ctx, robot, room.door_point("corridor", offset=stand_off(robot, SNEAK_OFFSET)))
    if way.points is None:
        return way.reason
    distance = yield from traverse(ctx, robot, way.points, sense=True)
    here = robot.position(ctx.env.now)
    into = math.atan2(room.center[1] - here[1], room.center[0] - here[0])
    turned = yield ctx.cosim.face(robot, into)  # turn the camera into the room
    if not turned.ok:
        raise MotionFailed(turned.reason, turned.fault)
    coverage = ctx.sensor.coverage(robot, here[None, :], room, headings=np.array([into]))
    yield from dwell(ctx, robot, seconds)
    return distance, coverage
