"""What every action uses: travelling a route, sensing along it, searching a room."""

from __future__ import annotations

from collections.abc import Generator
from typing import Any, Protocol

import numpy as np
import simpy

from astralis_des.kernel.robot import Motion, Robot
from astralis_des.kernel.tasks import ActionResult, Task, TaskStatus
from astralis_des.kinds import TARGET_HEIGHT
from astralis_des.planning.navigator import Navigator, Route
from astralis_des.sensing import GeometricSensor, Sighting
from astralis_des.world.geometry import FloatArray
from astralis_des.world.model import Room, World

ActionGen = Generator[simpy.Event, Any, ActionResult]
StepGen = Generator[simpy.Event, Any, float]


class CoSim(Protocol):
    def execute(self, robot: Robot, motion: Motion) -> simpy.Event: ...
    def watch(self, robot: Robot, motion: Motion, sensor: GeometricSensor,
              done: simpy.Event) -> simpy.Event: ...
    def dwell(self, robot: Robot, seconds: float) -> simpy.Event: ...
    def face(self, robot: Robot, heading: float) -> simpy.Event: ...
    def halt(self, robot: Robot) -> None: ...
    def look(self, robot: Robot, sensor: GeometricSensor) -> Sighting | None: ...


class MotionFailed(Exception):
    """A motion ended without arriving; the action ends ``failed`` with this reason."""


class Context(Protocol):
    """What a :class:`~astralis_des.kernel.simulation.Simulation` offers to actions."""

    env: simpy.Environment
    world: World
    cosim: CoSim
    sensor: GeometricSensor
    navigator: Navigator

    def report_detection(self, robot: Robot, sighting: Sighting) -> None: ...


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
    here = ctx.world.on_floor(robot.position(ctx.env.now))
    return ctx.navigator.route(robot, here, np.asarray(goal_floor, dtype=float))


def traverse(ctx: Context, robot: Robot, points: FloatArray, sense: bool) -> StepGen:
    """Follow ``points``; when sensing, report the target the moment it comes into view."""
    before = robot.distance
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
        raise MotionFailed(outcome.reason)
    return robot.distance - before


def dwell(ctx: Context, robot: Robot, seconds: float) -> StepGen:
    """Stay and look around from where the robot is."""
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
    sweep = at_height(robot, plan)
    coverage = ctx.sensor.coverage(robot, sweep, room)  # furnishes the room before going in
    sweep = ctx.navigator.usable(robot, sweep)  # where the body fits among the furniture
    if len(sweep) == 0:
        return failed(f"{label}: no point of the pattern is free in {room.id}")
    approach = route(ctx, robot, sweep[0] - np.array([0.0, 0.0, robot.height]))
    if approach.points is None:
        return failed(approach.reason)
    distance = yield from traverse(ctx, robot, approach.points, sense=False)
    refined = ctx.navigator.refine(robot, sweep) if ctx.navigator.method == "map" else None
    if refined is not None:
        if refined.points is None:
            return failed(refined.reason)
        sweep = refined.points
    distance += yield from traverse(ctx, robot, sweep, sense=True)
    return result(TaskStatus.SUCCEEDED, f"{label} saw {coverage:.0%} of {room.id}",
                  distance=distance, coverage=coverage)


def footprint_spacing(robot: Robot, overlap: float) -> float:
    """Distance between passes: the width the camera sees at the target's height, less the
    overlap (at least 0.5 m; 1 m for a robot without a camera)."""
    if robot.view is None:
        return 1.0
    swath = robot.view.swath(max(robot.height - TARGET_HEIGHT, 0.0))
    return float(max(swath * (1.0 - overlap), 0.5))


def plane_to_floor(room: Room, plane: FloatArray) -> FloatArray:
    return np.column_stack([plane, np.full(len(plane), room.box.lo[2])])
