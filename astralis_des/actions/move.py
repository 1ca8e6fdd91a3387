"""``move``: every kind goes to a place (a room's centre or door, or a point)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from astralis_des.action_spec import ActionParams, Number, Verb
from astralis_des.actions.common import ActionGen, Context, failed, go_to, room_of, stand_off
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import Task
from astralis_des.kinds import KINDS
from astralis_des.plugins import action


class MoveParams(ActionParams):
    point: Literal["center", "door"] = Field("center", description="with a room: where in it")
    x: Number | None = Field(None, description="m, a point to go to (with y)")
    y: Number | None = Field(None, description="m")
    z: Number = Field(0.0, description="m")
    look: Number = Field(0.0, ge=0.0, le=1.0, description="1: watch for the target on the way")


@action("move", tuple(KINDS), params=MoveParams, point=True,
        verbs=(Verb("move", "go to a room (its centre) or to a point x y"),))
def move(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Go to a room's centre (``point``: ``center``) or door (``door``), or to the point
    ``x``, ``y``, ``z``; ``look`` = 1: watch for the target on the way (teleoperation does)."""
    args = MoveParams.model_validate(dict(task.params))
    room = room_of(ctx, task)
    if room is not None:
        ctx.sensor.scene.furnish([room.id])  # its furniture is there before the robot is
        goal = room.center if args.point == "center" else room.door_point("corridor",
                                                                          stand_off(robot))
    elif args.x is not None and args.y is not None:
        goal = (args.x, args.y, args.z)
    else:
        return failed("move needs a room or x and y")
    return (yield from go_to(ctx, robot, goal, sense=bool(args.look)))
