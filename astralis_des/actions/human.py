"""The human operator's search action: walk into the room and look around it."""

from __future__ import annotations

from pydantic import Field

from astralis_des.action_spec import ActionParams, Number, Verb
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
from astralis_des.plugins import action
from astralis_des.world import coverage as cov


class InspectParams(ActionParams):
    inset: Number = Field(1.0, ge=0.0, le=20.0,
                          description="m from the walls of the walk round the room")


# Table IV has no human row; an assigned operator walks in and looks (our choice).
@action("inspect", ("human",), params=InspectParams, search=True, seconds_per_m2=0.377,
        table4=((False, False), (True, False), (False, True), (True, True)),
        verbs=(Verb("inspect", "walk into a room and inspect it"),
               Verb("search", "the same as inspect")))
def inspect(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Walk a loop ``inset`` metres inside the room's walls, looking around."""
    room = room_of(ctx, task)
    if room is None:
        return failed("inspect needs a room")
    inset = InspectParams.model_validate(dict(task.params)).inset
    plane = cov.loop(room.box, inset)
    plane = cov.start_near(plane, room.box, room.door_point("room"))  # type: ignore[arg-type]
    plane = cov.within(plane, room.outline, inset)
    return (yield from search_path(ctx, robot, room, plane_to_floor(room, plane), "inspect"))
