"""Commands: tasks for robots, the clock, assignment rounds, teleoperation. Each checks its
arguments against the mission first, then is logged as a ``command`` event, then acts."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from pydantic import Field

from astralis_des.actions import ACTIONS, actions_for
from astralis_des.api.ops import Args, NoArgs, op
from astralis_des.api.protocol import MAX_PACE, MAX_TELEOP_STEP, ApiError
from astralis_des.errors import InputError, suggest
from astralis_des.simulation.timeline import book, dispatch

if TYPE_CHECKING:
    from astralis_des.api.session import Session
    from astralis_des.kernel.robot import Robot

COMPASS = {"north": (0.0, 1.0), "south": (0.0, -1.0), "east": (1.0, 0.0),
           "west": (-1.0, 0.0)}
Param = float | str


class TaskArgs(Args):
    robot: str
    action: str
    room: str | None = None
    params: dict[str, Param] = Field(default_factory=dict, max_length=16)


class EnqueueArgs(TaskArgs):
    preempt: bool = False


class CancelArgs(Args):
    robot: str
    task: int | None = Field(None, description="a task id; none: all of the robot's tasks")


class ResumeArgs(Args):
    pace: float | None = Field(None, gt=0.0, le=MAX_PACE)


class StepArgs(Args):
    until: float | None = Field(None, description="simulated s to run to")
    by: float | None = Field(None, gt=0.0, description="simulated s to run for")


class AssignArgs(Args):
    segment: str
    rooms: list[str] | None = Field(None, description="some of the segment's rooms")
    robots: list[str] | None = Field(None, description="the agents; default: all not faulted")


class TeleopArgs(Args):
    robot: str
    direction: Literal["north", "south", "east", "west"]
    distance: float = Field(0.5, gt=0.0, le=MAX_TELEOP_STEP)


def _task(svc: Session, args: TaskArgs) -> Robot:
    """Check a task against the robot's kind, the world and the robot's state."""
    robot = svc.robot(args.robot)
    if (robot.kind, args.action) not in ACTIONS:
        raise ApiError("bad_action", f"{robot.id} is a {robot.kind} and has no action "
                       f"'{args.action}'; its actions: {', '.join(actions_for(robot.kind))}")
    spec = ACTIONS.get((robot.kind, args.action))
    if args.room is not None:
        svc.room(args.room)
    elif spec.room and not (spec.point and {"x", "y"} <= set(args.params)):
        what = "a room or params x and y" if spec.point else "a room"
        raise ApiError("bad_args", f"{args.action} needs {what}")
    for key, value in args.params.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise ApiError("bad_args", f"params.{key} must be finite")
    try:
        spec.check(dict(args.params))
    except ValueError as exc:
        raise ApiError("bad_args", str(exc)) from None
    if robot.faulted:
        raise ApiError("faulted", f"{robot.id} is down after a fault; it takes no tasks "
                       "until it recovers")
    return robot


def _queued(svc: Session, args: TaskArgs, preempt: bool) -> dict[str, Any]:
    robot = _task(svc, args)
    handler = svc.sim.handler(robot.id)
    running = handler.current
    svc.command_event("preempt" if preempt else "enqueue", robot.id, action=args.action,
                      room=args.room, params=dict(args.params) or None)
    svc.sim.enqueue(robot.id, args.action, args.room, dict(args.params), origin="api",
                    preempt=preempt)
    task = max(handler.queued, key=lambda t: t.id)  # ids only grow
    out: dict[str, Any] = {"task": task.id, "robot": robot.id,
                           "position": handler.queued.index(task)}
    if preempt:
        out["interrupted"] = running.id if running is not None else None
    return out


@op("enqueue", EnqueueArgs, command=True)
def _enqueue(svc: Session, args: EnqueueArgs) -> dict[str, Any]:
    """Queue a task for a robot (after its others, or first with preempt: true)."""
    return _queued(svc, args, args.preempt)


@op("preempt", TaskArgs, command=True)
def _preempt(svc: Session, args: TaskArgs) -> dict[str, Any]:
    """Run a task now: the running task ends 'preempted', the queue waits behind."""
    return _queued(svc, args, True)


@op("cancel", CancelArgs, command=True)
def _cancel(svc: Session, args: CancelArgs) -> dict[str, Any]:
    """Cancel one task of a robot, running or queued, or all of them."""
    robot = svc.robot(args.robot)
    handler = svc.sim.handler(robot.id)
    if args.task is not None:
        ids = [t.id for t in ([handler.current] if handler.current else []) + handler.queued]
        if args.task not in ids:
            have = ", ".join(map(str, ids)) or "none"
            raise ApiError("unknown_task", f"{robot.id} has no task {args.task} "
                           f"(its tasks: {have})")
    svc.command_event("cancel", robot.id, task=args.task)
    cancelled = handler.cancel(args.task, reason="cancelled through the API")
    return {"robot": robot.id, "cancelled": [t.id for t in cancelled]}


@op("pause", NoArgs, command=True)
def _pause(svc: Session, args: Args) -> dict[str, Any]:
    """Stop the clock; time then moves only on step (or resume)."""
    svc.command_event("pause")
    svc.clock.running = False
    return {"t": svc.now, "clock": svc.clock.describe()}


@op("resume", ResumeArgs, command=True)
def _resume(svc: Session, args: ResumeArgs) -> dict[str, Any]:
    """Start the clock again, at the pace given or the one it had."""
    svc.command_event("resume", pace=args.pace)
    if args.pace is not None:
        svc.clock.pace = args.pace
    svc.clock.running = True
    svc.clock.anchor(svc.now)
    return {"t": svc.now, "clock": svc.clock.describe()}


@op("step", StepArgs, command=True)
def _step(svc: Session, args: StepArgs) -> dict[str, Any]:
    """With the clock paused: run the mission to a time (until) or for a while (by)."""
    if svc.clock.running:
        raise ApiError("clock_running", f"the clock is {svc.clock.describe()}; pause it first "
                       "(or serve with --stepped)")
    if (args.until is None) == (args.by is None):
        raise ApiError("bad_args", "step: give one of 'until' (a time) or 'by' (seconds)")
    until = args.until if args.until is not None else svc.now + float(args.by or 0.0)
    if not math.isfinite(until) or until <= svc.now:
        raise ApiError("bad_args", f"step: until = {until:g} s is not after now "
                       f"({svc.now:g} s)")
    svc.command_event("step", until=until)
    svc.advance(until)
    svc.clock.anchor(svc.now)
    return {"t": svc.now, "ended": svc.ended,
            "outcome": svc.result.outcome if svc.result is not None else None}


@op("assign", AssignArgs, command=True)
def _assign(svc: Session, args: AssignArgs) -> dict[str, Any]:
    """Run an assignment round now (Eq. 1) over a segment's rooms and queue its tasks."""
    sim = svc.sim
    segment = sim.world.segments.get(args.segment)
    if segment is None:
        raise ApiError("unknown_segment", f"no segment '{args.segment}'; "
                       f"{suggest(args.segment, sim.world.segments)}")
    rooms = list(args.rooms) if args.rooms is not None else list(segment.rooms)
    for room in rooms:
        if svc.room(room).segment != args.segment:
            raise ApiError("bad_args", f"room {room} is not in segment {args.segment}")
    if not rooms:
        raise ApiError("bad_args", "assign: no rooms to assign")
    names = args.robots if args.robots is not None else list(sim.robots)
    robots = [svc.robot(name) for name in names]
    agents = [r for r in robots if not r.faulted]
    if not agents:
        raise ApiError("no_agents", "no robot that is not faulted to assign")
    svc.command_event("assign", segment=args.segment, rooms=args.rooms, robots=args.robots)
    plan = sim.assignment_round(args.segment, rooms, agents)
    sim.env.process(book(sim, dispatch(sim, plan)))
    record = sim.rounds[-1]
    return {"round": record["round"], "matching": record["matching"],
            "unassigned": record["unassigned"]}


@op("teleop", TeleopArgs, command=True)
def _teleop(svc: Session, args: TeleopArgs) -> dict[str, Any]:
    """Walk (drive, fly) a robot a step north, south, east or west, now; steps add up."""
    robot = svc.robot(args.robot)
    if robot.faulted:
        raise ApiError("faulted", f"{robot.id} is down after a fault")
    sim = svc.sim
    handler = sim.handler(robot.id)
    last = svc.teleop_goals.get(robot.id)
    here = sim.world.on_floor(robot.position(svc.now))
    pending = [handler.current, *handler.queued] if handler.current else handler.queued
    going = last is not None and any(t.id == last[0] for t in pending)  # not there yet
    base = last[1] if going and last is not None else here
    dx, dy = COMPASS[args.direction]
    goal = np.array([base[0] + dx * args.distance, base[1] + dy * args.distance, base[2]])
    _check_step(svc, robot, here, goal)
    svc.command_event("teleop", robot.id, direction=args.direction, distance=args.distance)
    if going and last is not None and any(t.id == last[0] for t in handler.queued):
        handler.cancel(last[0], reason="superseded by the next teleop step")
    params = {"x": float(goal[0]), "y": float(goal[1]), "z": float(goal[2]), "look": 1.0}
    sim.enqueue(robot.id, "move", None, params, origin="teleop", preempt=True)
    task = max(handler.queued, key=lambda t: t.id)
    svc.teleop_goals[robot.id] = (task.id, goal)
    return {"task": task.id, "robot": robot.id, "goal": goal.tolist()}


def _check_step(svc: Session, robot: Robot, here: np.ndarray, goal: np.ndarray) -> None:
    """A teleoperated step goes straight: not off the site, into a wall or round one."""
    world = svc.sim.world
    where = ", ".join(f"{v:.2f}" for v in goal[:2])
    try:
        way = world.router.route(here, goal, robot.kind)
    except InputError as exc:
        raise ApiError("blocked", f"{robot.id} cannot step to [{where}]: {exc.message}") from None
    if way is None:
        raise ApiError("blocked", f"{robot.id} cannot step to [{where}]: no way there")
    length = float(np.sum(np.linalg.norm(np.diff(way, axis=0), axis=1)))
    straight = float(np.linalg.norm(goal - here))
    if length > 1.5 * straight + 0.5:
        raise ApiError("blocked", f"{robot.id} cannot step to [{where}]: a wall is in the way")


@op("shutdown", NoArgs, command=True)
def _shutdown(svc: Session, args: Args) -> dict[str, Any]:
    """End the mission where it is (its outputs are written) and stop the server."""
    if not svc.ended:
        svc.command_event("shutdown")
    svc.stopping = True
    return {"t": svc.now}
