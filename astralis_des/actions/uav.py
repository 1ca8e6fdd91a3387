"""UAV actions of Table I: hover, inward and outward spiral search, vertical and horizontal
sweep."""

from __future__ import annotations

from pydantic import Field

from astralis_des.action_spec import ActionParams, Number, Verb
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
from astralis_des.plugins import action
from astralis_des.world import coverage as cov

OVERLAP = 0.2  # share of the footprint that neighbouring passes see twice
WALL_MARGIN = 1.0  # m: the outermost pass runs at most this far inside the walls, so that the
# camera, which looks ahead and down, sees the strip along each wall


class SearchParams(ActionParams):
    spacing: Number | None = Field(None, ge=0.1, le=50.0, description="m between lanes or rings "
                            "(default: from the camera's footprint)")


class HoverParams(ActionParams):
    duration: Number = Field(10.0, ge=0.0, le=86400.0,
                             description="s to hold position and look around")


def _pattern(name: str, inward: bool | None = None, axis: int | None = None):  # type: ignore[no-untyped-def]
    def run(ctx: Context, robot: Robot, task: Task) -> ActionGen:
        room = room_of(ctx, task)
        if room is None:
            return failed(f"{name} needs a room")
        spacing = SearchParams.model_validate(dict(task.params)).spacing
        if spacing is None:
            spacing = footprint_spacing(robot, OVERLAP)
        if axis is None:
            plane = cov.spiral(room.box, spacing, inward=bool(inward), margin=WALL_MARGIN)
        else:
            plane = cov.lawnmower(room.box, spacing, axis, margin=WALL_MARGIN)
        entry = room.door_point("room")
        plane = cov.start_near(plane, room.box, entry)  # type: ignore[arg-type]
        plane = cov.within(plane, room.outline, WALL_MARGIN)
        return (yield from search_path(ctx, robot, room, plane_to_floor(room, plane), name))

    run.__name__ = name
    run.__doc__ = f"{name.replace('_', ' ')} over the room, passes ``spacing`` apart."
    return run


# Seconds per m^2 measured as astralis_des/assignment/durations.py says; the Table IV cells are
# (high risk, high messiness): risk comes first, a high-risk room gets the inward spiral.
_SEARCH = "search a room: a spiral (inward, the default, or outward) or a sweep (horizontal, " \
    "vertical)"
for _name, _inward, _axis, _s, _cells, _word in (
    ("spiral_inward", True, None, 0.437, ((True, False), (True, True)), "inward"),
    ("spiral_outward", False, None, 0.432, ((False, False),), "outward"),
    ("sweep_horizontal", None, 0, 0.439, ((False, True),), "horizontal"),
    ("sweep_vertical", None, 1, None, (), "vertical"),
):
    action(_name, ("uav",), params=SearchParams, search=True, seconds_per_m2=_s, table4=_cells,
           verbs=(Verb("search", _SEARCH if _inward else "", variant=_word),))(
        _pattern(_name, _inward, _axis))


@action("hover", ("uav",), params=HoverParams, room=False,
        verbs=(Verb("hover", "hold position and look around", number="duration"),))
def hover(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Hold position and look around for ``duration`` seconds."""
    seconds = HoverParams.model_validate(dict(task.params)).duration
    yield from dwell(ctx, robot, seconds)
    return result(TaskStatus.SUCCEEDED, f"hovered {seconds:g} s")


@action("take_off", ("uav",), room=False,
        verbs=(Verb("take-off", "climb from the ground to the flight height"),))
def take_off_action(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Climb straight up from the ground to the flight height (a UAV on the ground also
    does this by itself before any other action)."""
    flying = robot.airborne
    distance = yield from take_off(ctx, robot)
    return result(TaskStatus.SUCCEEDED, "already flying" if flying else "took off",
                  distance=distance)


@action("land", ("uav",), room=False,
        verbs=(Verb("land", "come down onto the floor below (the next action takes off "
                    "again)"),))
def land_action(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Come straight down onto the floor below and stay there (the next action takes off
    again). UAVs land by themselves when the mission ends."""
    flying = robot.airborne
    distance = yield from land(ctx, robot)
    return result(TaskStatus.SUCCEEDED, "landed" if flying else "already on the ground",
                  distance=distance)
