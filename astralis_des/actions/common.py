"""What every action uses: travelling a route, sensing along it, searching a room."""

from __future__ import annotations

from collections.abc import Generator
from typing import Any

import numpy as np
import simpy

from astralis_des import detection
from astralis_des.kernel.contracts import Context
from astralis_des.kernel.robot import Motion, Robot
from astralis_des.kernel.tasks import ActionResult, Task, TaskStatus
from astralis_des.kinds import CLIMB_SPEED, KIND_DEFAULTS, TARGET_HEIGHT
from astralis_des.planning.navigator import Route, level_legs
from astralis_des.world.geometry import FloatArray
from astralis_des.world.model import Room

DOOR_OFFSET = 0.6  # m in front of a door's wall: where robots stop by a door
TURN_MARGIN = 0.1  # m kept between a wall and the circle a body sweeps turning on the spot
LOOK_AROUND = 2.0  # s spent looking round a room that cannot be searched by its pattern
ActionGen = Generator[simpy.Event, Any, ActionResult]
StepGen = Generator[simpy.Event, Any, float]


class MotionFailed(Exception):
    """A motion ended without arriving; the action ends ``failed`` with this reason. With
    ``fault`` the robot cannot go on (it crashed): it is faulted and leaves the mission."""

    def __init__(self, reason: str, fault: bool = False) -> None:
        super().__init__(reason)
        self.fault = fault


def result(status: TaskStatus, message: str, **kw: Any) -> ActionResult:
    return ActionResult(status, message, **kw)


def failed(message: str) -> ActionResult:
    return ActionResult(TaskStatus.FAILED, message)


def room_of(ctx: Context, task: Task) -> Room | None:
    return ctx.world.rooms.get(task.room) if task.room else None


def at_height(robot: Robot, floor_points: FloatArray) -> FloatArray:
    pts = np.array(floor_points, dtype=float)
    pts[:, 2] += robot.height
    return pts


def route(ctx: Context, robot: Robot,
          goal_floor: FloatArray | tuple[float, ...]) -> Route:
    """Route from where the robot is to a floor-level goal, at the robot's sensor height."""
    now = robot.position(ctx.env.now)
    return ctx.navigator.route(robot, ctx.world.on_floor(now), np.asarray(goal_floor, dtype=float),
                               at=now if KIND_DEFAULTS[robot.kind].flies else None)


def climb(ctx: Context, robot: Robot, height: float) -> StepGen:
    """Fly straight up or down to ``height`` above the floor under the robot."""
    here = robot.position(ctx.env.now)
    there = here.copy()
    there[2] = ctx.world.floor_below(here) + height
    before = robot.distance
    done = ctx.cosim.execute(robot, Motion(np.vstack([here, there]), CLIMB_SPEED,
                                           accel=robot.accel, heading=robot.heading))
    outcome = yield done
    ctx.cosim.halt(robot)
    if not outcome.ok:
        raise MotionFailed(outcome.reason, outcome.fault)
    return robot.distance - before


def take_off(ctx: Context, robot: Robot) -> StepGen:
    """A UAV on the ground climbs to its flight height before it goes anywhere (a
    ``took_off`` event); nothing for a robot already flying or one that does not fly."""
    if robot.airborne:
        return 0.0
    distance = yield from climb(ctx, robot, robot.height)
    robot.airborne = True
    ctx.log.emit("took_off", robot.id, height=round(robot.height, 3))
    return distance


def traverse(ctx: Context, robot: Robot, points: FloatArray, sense: bool) -> StepGen:
    """Follow ``points``; when sensing, report the target the moment it comes into view.
    A UAV on the ground takes off first."""
    before = robot.distance
    yield from take_off(ctx, robot)
    robot.plans.append((ctx.env.now, np.asarray(points, dtype=float)))
    motion = Motion(points, robot.speed, accel=robot.accel, turn_rate=robot.turn_rate,
                    heading=robot.heading)
    done = ctx.cosim.execute(robot, motion)
    if sense:
        seen = ctx.cosim.watch(robot, motion, ctx.sensor, done)
        yield seen | done
        if seen.triggered and seen.value is not None:
            ctx.report_detection(robot, seen.value)
    outcome = yield done
    ctx.cosim.halt(robot)
    if not outcome.ok:
        raise MotionFailed(outcome.reason, outcome.fault)
    return robot.distance - before


def dwell(ctx: Context, robot: Robot, seconds: float) -> StepGen:
    """Stay and look around from where the robot is (a UAV on the ground takes off first)."""
    yield from take_off(ctx, robot)
    ctx.cosim.halt(robot)
    hit = ctx.cosim.look(robot, ctx.sensor)
    if hit is not None:
        ctx.report_detection(robot, hit)
    yield ctx.cosim.dwell(robot, seconds)
    return 0.0


def go_to(ctx: Context, robot: Robot, goal_floor: tuple[float, ...],
          sense: bool = False) -> ActionGen:
    way = route(ctx, robot, goal_floor)
    if way.points is None:
        return failed(way.reason)
    distance = yield from traverse(ctx, robot, way.points, sense=sense)
    return result(TaskStatus.SUCCEEDED, "arrived", distance=distance)


def search_path(ctx: Context, robot: Robot, room: Room, plan: FloatArray, label: str) -> ActionGen:
    """Go to the start of a coverage path ``plan`` (floor level) and follow it, sensing."""
    ctx.sensor.scene.furnish([room.id])  # the room is furnished before the robot goes in
    pattern = at_height(robot, plan)
    fitting = ctx.navigator.usable(robot, pattern)  # where the body fits among the furniture
    assert fitting.points is not None
    sweep, skipped = fitting.points, fitting.skipped
    if len(sweep) == 0:
        return (yield from _from_the_door(ctx, robot, room, label))
    for entry in range(len(sweep)):  # the first point it can get to starts the pattern
        approach = route(ctx, robot, ctx.world.on_floor(sweep[entry]))
        if approach.points is not None:
            break
    if approach.points is None:
        return failed(approach.reason)
    skipped += entry
    sweep = level_legs(np.vstack([approach.points[-1:], sweep[entry:]]))[1:]
    distance = yield from traverse(ctx, robot, approach.points, sense=False)
    if ctx.navigator.method == "map":  # unreachable points are left out, not the search
        refined = ctx.navigator.refine(robot, sweep, skip=True)
        assert refined.points is not None
        sweep, skipped = refined.points, skipped + refined.skipped
    coverage = ctx.sensor.coverage(robot, sweep, room)
    note = f" ({skipped} of {len(pattern)} points out of reach)" if skipped else ""
    distance += yield from traverse(ctx, robot, sweep, sense=True)
    return result(TaskStatus.SUCCEEDED, f"{label} saw {coverage:.0%} of {room.id}{note}",
                  distance=distance, coverage=coverage, extra={"skipped": skipped})


def _from_the_door(ctx: Context, robot: Robot, room: Room, label: str) -> ActionGen:
    """A pattern with no point the body fits at (a crammed room): look around from just
    inside the door instead, and say so."""
    inside = at_height(robot, np.array([room.door_point("room", DOOR_OFFSET)]))
    door = ctx.navigator.usable(robot, inside).points
    if door is None or not len(door):
        return failed(f"{label}: no point of the pattern is free in {room.id}, nor the door")
    way = route(ctx, robot, inside[0] - np.array([0.0, 0.0, robot.height]))
    if way.points is None:
        return failed(way.reason)
    distance = yield from traverse(ctx, robot, way.points, sense=False)
    yield from dwell(ctx, robot, LOOK_AROUND)
    headings = np.linspace(0.0, 2 * np.pi, 8, endpoint=False)
    coverage = ctx.sensor.coverage(robot, np.repeat(inside, len(headings), axis=0), room,
                                   headings=headings)
    return result(TaskStatus.SUCCEEDED, f"{label}: no point of the pattern is free in "
                  f"{room.id}; looked round from the door, saw {coverage:.0%}",
                  distance=distance, coverage=coverage)


def stand_off(robot: Robot, least: float = DOOR_OFFSET) -> float:
    """How far from a wall's face the robot stops to be able to turn on the spot there: a
    long body (the UGV) needs its half-diagonal and a margin, others ``least``."""
    swept = KIND_DEFAULTS[robot.kind].swept_radius
    return least if swept is None else max(least, swept + TURN_MARGIN)


def footprint_spacing(robot: Robot, overlap: float) -> float:
    """Distance between passes: the width the camera sees at the target's height, less the
    overlap (at least 0.5 m; 1 m for a robot without a camera)."""
    if robot.view is None:
        return 1.0
    swath = detection.swath(robot.view, max(robot.height - TARGET_HEIGHT, 0.0))
    return float(max(swath * (1.0 - overlap), 0.5))


def plane_to_floor(room: Room, plane: FloatArray) -> FloatArray:
    return np.column_stack([plane, np.full(len(plane), room.box.lo[2])])
