"""Queries: the paper's Table II (avatar, location, robot) and the mission's status, task
queues and events. They change nothing and are never logged."""

from __future__ import annotations

import bisect
from typing import TYPE_CHECKING, Any

import numpy as np
from pydantic import Field

from astralis_des.actions import actions_for
from astralis_des.api.ops import OPS, Args, op
from astralis_des.api.protocol import MAX_MESSAGE, PROTOCOL, ApiError
from astralis_des.errors import suggest
from astralis_des.kernel.catalogue import EVENTS
from astralis_des.version import __version__

if TYPE_CHECKING:
    from astralis_des.api.session import Session
    from astralis_des.kernel.robot import Robot
    from astralis_des.kernel.tasks import Task

TABLE_II_AVATAR = {"activity": "activity", "color": "color", "gender": "gender",
                   "height": "height", "tied_to_chair": "tiedToChair"}
MAX_EVENTS = 5000


class RobotArgs(Args):
    robot: str


class OptionalRobot(Args):
    robot: str | None = None


class RoomArgs(Args):
    room: str


class EventsArgs(Args):
    since: float | None = Field(None, description="simulated s: events at or after it")
    after: int = Field(0, ge=0, description="events after this many (a reply's 'next')")
    kinds: list[str] | None = None
    robot: str | None = None
    limit: int = Field(1000, ge=1, le=MAX_EVENTS)
    last: int | None = Field(None, ge=1, le=MAX_EVENTS, description="only the last N of them")


@op("help")
def _help(svc: Session, args: Args) -> dict[str, Any]:
    """The operations, their arguments (! = required) and what each does."""
    return {"ops": {name: {"usage": OPS.get(name).usage(), "help": OPS.get(name).help,
                           "command": OPS.get(name).command} for name in OPS}}


@op("info")
def _info(svc: Session, args: Args) -> dict[str, Any]:
    """The mission, its team and their actions, the rooms, segments and addresses."""
    sim, spec = svc.sim, svc.sim.mission.spec
    world = sim.world
    return {
        "protocol": PROTOCOL, "version": __version__, "mission": spec.name, "seed": spec.seed,
        "fidelity": spec.fidelity, "world": world.name, "time_limit": spec.time_limit,
        "robots": {r.id: {"type": r.kind, "actions": actions_for(r.kind)}
                   for r in sim.robots.values()},
        "rooms": sorted(world.rooms),
        "segments": {sid: list(seg.rooms) for sid, seg in world.segments.items()},
        "auto_assignment": spec.assignment.auto, "max_message": MAX_MESSAGE,
        "addresses": dict(svc.addresses),
    }


@op("status", OptionalRobot)
def _status(svc: Session, args: OptionalRobot) -> dict[str, Any]:
    """The mission's time, clock, outcome and each robot's state (or one robot's)."""
    sim = svc.sim
    robots = ([svc.robot(args.robot)] if args.robot is not None
              else list(sim.robots.values()))
    return {
        "t": svc.now, "clock": svc.clock.describe(), "running": svc.clock.running,
        "pace": svc.clock.pace, "ended": svc.ended,
        "outcome": svc.result.outcome if svc.result is not None else None,
        "found": sim.found.triggered,
        "found_by": sim.found.value if sim.found.triggered else None,  # the finder's id
        "rounds": len(sim.rounds), "rooms_searched": list(sim.searched),
        "robots": {r.id: robot_state(svc, r) for r in robots},
    }


class AvatarArgs(Args):
    avatar: str | None = Field(None, description="a bystander's id, e.g. A.1.1.2/avatar-0 "
                               "(from 'avatars'); none: the target")


class AvatarsArgs(Args):
    room: str | None = Field(None, description="only this room's")


def bystanders(svc: Session, rooms: list[str]) -> dict[str, Any]:
    """``ROOM/avatar-N`` -> the placed avatar, for the rooms already furnished (a room is
    furnished when the team first looks into it, in kinematic fidelity; all at the start in
    physics): querying never furnishes one, which would change the mission."""
    scene = svc.sim.scene
    furnished = {p.room for p in scene.furnished()}
    out: dict[str, Any] = {}
    for rid in rooms:
        if rid in furnished:
            mine = [p for p in scene.clutter(rid).placed if p.kind == "avatar"]
            out.update({f"{rid}/avatar-{i}": p for i, p in enumerate(mine)})
    return out


def _bystander(svc: Session, ident: str, placed: Any) -> dict[str, Any]:
    out: dict[str, Any] = {"id": ident, "room": placed.room, "target": False}
    out.update({TABLE_II_AVATAR[k]: v for k, v in placed.attributes})
    out["location"] = [round(float(v), 3) for v in placed.center]
    scene = svc.sim.scene
    walking = scene.patrolling(placed.room)
    if placed in walking:  # where it is on its loop now
        mover = scene.avatar_movers([placed.room])[walking.index(placed)]
        out["location"] = [round(float(v), 3) for v in mover.positions_at(
            np.array([svc.now]))[0]]
    return out


@op("avatar", AvatarArgs)
def _avatar(svc: Session, args: AvatarArgs) -> dict[str, Any]:
    """An avatar's attributes (Table II): the target's (its location once it has been found),
    or with ``avatar`` (an id) a bystander's, with its room and where it is."""
    if args.avatar is not None:
        room = args.avatar.split("/", 1)[0]
        known = bystanders(svc, [svc.room(room).id])
        if args.avatar not in known:
            hint = suggest(args.avatar, known) if known else f"none in {room} yet"
            raise ApiError("unknown_avatar", f"no avatar '{args.avatar}'; {hint} (the "
                           "avatars query lists them)")
        return _bystander(svc, args.avatar, known[args.avatar])
    target = svc.sim.target
    out: dict[str, Any] = {TABLE_II_AVATAR[k]: v for k, v in target.avatar.items()}
    out["found"] = svc.sim.found.triggered
    if out["found"]:
        out["location"] = list(target.position)
        out["room"] = target.room
    return out


@op("avatars", AvatarsArgs)
def _avatars(svc: Session, args: AvatarsArgs) -> dict[str, Any]:
    """The bystanders of the rooms furnished so far (or of ``room``): id, room, Table II
    attributes; the target is not among them."""
    rooms = [svc.room(args.room).id] if args.room is not None else sorted(svc.sim.world.rooms)
    found = bystanders(svc, rooms)
    return {"avatars": [{"id": ident, "room": p.room,
                         **{TABLE_II_AVATAR[k]: v for k, v in p.attributes}}
                        for ident, p in found.items()]}


@op("location", RoomArgs)
def _location(svc: Session, args: RoomArgs) -> dict[str, Any]:
    """A room's location, messiness_level, risk and sound (Table II)."""
    room = svc.room(args.room)
    state = svc.sim.rooms[room.id]
    return {"room": room.id, "location": list(room.center), "messiness_level": state.messiness,
            "risk": state.risk, "sound": state.sound, "segment": room.segment,
            "searched": room.id in svc.sim.searched}


@op("robot", RobotArgs)
def _robot(svc: Session, args: RobotArgs) -> dict[str, Any]:
    """A robot's type, pose and command (Table II), and its state."""
    return robot_state(svc, svc.robot(args.robot))


class ReadingArgs(Args):
    robot: str
    sensor: str = Field(description="gnss, barometer or magnetometer")


@op("reading", ReadingArgs)
def _reading(svc: Session, args: ReadingArgs) -> dict[str, Any]:
    """The latest reading of a robot's GNSS, barometer or magnetometer (at or before now)."""
    robot = svc.robot(args.robot)
    sensors = svc.sim.pose_sensors
    carried = sorted(name for rid, name in sensors.sensors if rid == robot.id)
    if args.sensor not in carried:
        raise ApiError("bad_request", f"{robot.id} carries no {args.sensor!r}; its pose "
                       f"sensors: {', '.join(carried) or 'none'}")
    sensors.update(float(svc.sim.env.now))
    got = sensors.readings(robot.id, args.sensor)
    return {"robot": robot.id, "sensor": args.sensor,
            "reading": got.row(len(got) - 1) if len(got) else None}


@op("queue", RobotArgs)
def _queue(svc: Session, args: RobotArgs) -> dict[str, Any]:
    """A robot's running task and the tasks waiting, in the order they will run."""
    robot = svc.robot(args.robot)
    handler = svc.sim.handler(robot.id)
    current, queued = handler.view()
    return {"robot": robot.id, "current": task_dict(current) if current is not None else None,
            "queued": [task_dict(t) for t in queued]}


@op("events", EventsArgs)
def _events(svc: Session, args: EventsArgs) -> dict[str, Any]:
    """The log's events at or after ``since`` and past ``after``, oldest first (or only the
    ``last`` N); ``next`` is the ``after`` of the following page, ``total`` the log's length."""
    records = svc.sim.log.records
    kinds = set(args.kinds) if args.kinds is not None else None
    for kind in sorted(kinds or ()):  # a typo would select nothing, silently
        if kind not in EVENTS:
            raise ApiError("unknown_kind", f"no event kind '{kind}'; {suggest(kind, EVENTS)}")

    start = args.after
    since = args.since
    if since is not None and svc.sim.log.in_order:  # skip to ``since`` at once
        start = max(start, bisect.bisect_left(records, since, key=_time))
        since = None

    def wanted(rec: dict[str, Any]) -> bool:
        return ((since is None or rec["t"] >= since)
                and (kinds is None or rec["kind"] in kinds)
                and (args.robot is None or rec.get("robot") == args.robot))

    out: list[dict[str, Any]] = []
    if args.last is not None:  # from the end backwards, then in order
        index = len(records)
        for back in range(len(records) - 1, start - 1, -1):
            if wanted(records[back]):
                out.append(records[back])
                if len(out) == args.last:
                    break
        return {"events": out[::-1], "next": index, "total": index, "t": svc.now}
    index = start
    while index < len(records) and len(out) < args.limit:
        rec = records[index]
        index += 1
        if wanted(rec):
            out.append(rec)
    return {"events": out, "next": index, "total": len(records), "t": svc.now}


def _time(rec: dict[str, Any]) -> float:
    return float(rec["t"])


# -- shared with the state stream ----------------------------------------------------------
def robot_state(svc: Session, robot: Robot) -> dict[str, Any]:
    now = svc.now
    handler = svc.sim.handler(robot.id)
    current, queued = handler.view()
    position = robot.position(now)
    travelled = robot.motion.travelled(now) if robot.motion is not None else 0.0
    state = "faulted" if robot.faulted else ("busy" if current is not None else "idle")
    return {"id": robot.id, "type": robot.kind, "pose": [float(v) for v in position],
            "heading": heading_of(robot, now), "state": state,
            "command": current.describe() if current is not None else None,
            "task": current.id if current is not None else None,
            "queued": len(queued), "distance": robot.distance + travelled}


def heading_of(robot: Robot, now: float) -> float:
    """Radians from +x: along the kinematic path, or from the physics body."""
    if robot.motion is not None:
        return robot.motion.heading_at(now, robot.heading)
    return float(robot.heading)


def task_dict(task: Task) -> dict[str, Any]:
    return {"id": task.id, "action": task.action, "room": task.room,
            "params": dict(task.params), "origin": task.origin, "round": task.round}
