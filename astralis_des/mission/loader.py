"""Load a mission file: validate it, load its world, and check every reference in it."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from astralis_des.errors import suggest
from astralis_des.mission.imports import load_entry_points, load_named
from astralis_des.mission.spec import CommandEvent, MissionSpec
from astralis_des.plugins import ACTIONS, SENSORS, STRATEGIES, actions_for, check_params
from astralis_des.registry import UnknownEntry
from astralis_des.validation import check_unique_ids, validate
from astralis_des.world.build import load_world
from astralis_des.world.catalogue import Catalogue, default_catalogue, load_catalogue
from astralis_des.world.model import World
from astralis_des.world.placement import problem
from astralis_des.yamlio import KeyPath, LocatedYaml, load_yaml


@dataclass(frozen=True)
class Mission:
    """A validated mission with its world; what a :class:`Simulation` runs."""

    spec: MissionSpec
    world: World
    path: Path | None = None
    catalogue: Catalogue | None = None  # None: the packaged default

    def clutter_catalogue(self) -> Catalogue:
        return self.catalogue if self.catalogue is not None else default_catalogue()

    @property
    def name(self) -> str:
        return self.spec.name

    def with_changes(self, **changes: Any) -> Mission:
        """A copy with top-level spec fields replaced (e.g. ``seed=3``), checked like a file."""
        data = self.spec.model_dump(mode="json")
        data.update(changes)
        doc = LocatedYaml(data, {}, self.path or Path("<mission>"))
        spec = _validate(doc)
        _check_references(spec, self.world, doc)
        return replace(self, spec=spec)

    def searched_rooms(self) -> list[str]:
        """Rooms of the searched buildings or segments, in search order."""
        return [r for seg in self.searched_segments() for r in self.world.segments[seg].rooms]

    def searched_segments(self) -> list[str]:
        order: list[str] = []
        for entry in self.spec.assignment.search:
            segs = (self.world.segment_order(entry) if entry in self.world.groups
                    else [entry])
            order.extend(s for s in segs if s not in order)
        return order


def load_mission(path: str | Path) -> Mission:
    """Read a mission file; any problem is an :class:`InputError` naming file, line and key."""
    doc = load_yaml(path)
    load_entry_points()  # installed packages' plug-ins, then the mission's own: their
    load_named(doc)  # actions, strategies and sensors are names the mission may use
    spec = _validate(doc)
    world = load_world(doc.file_at(("world",), spec.world, "world file"))
    _check_references(spec, world, doc)
    catalogue = None
    if spec.scene.catalogue is not None:
        catalogue = load_catalogue(doc.file_at(("scene", "catalogue"), spec.scene.catalogue,
                                               "catalogue file"))
    return Mission(spec, world, doc.file, catalogue)


def _validate(doc: LocatedYaml) -> MissionSpec:
    check_unique_ids(doc, "team")
    spec = validate(MissionSpec, doc)
    _check_imu_rates(spec, doc)
    return spec


def _check_imu_rates(spec: MissionSpec, doc: LocatedYaml) -> None:
    """An IMU reads the physics state at controller ticks: it cannot read faster."""
    control = spec.physics.control_rate
    for i, member in enumerate(spec.team):
        imu = member.sensor_set.imu
        if imu is not None and imu.rate > control:
            where: KeyPath = (("team", i, "sensors", "imu", "rate") if member.sensors is not None
                              else ("physics", "control_rate"))
            raise doc.error(where, f"the IMU of {member.id} reads at {imu.rate:g} Hz, faster "
                            f"than the physics control_rate {control} Hz")


def _check_references(spec: MissionSpec, world: World, doc: LocatedYaml) -> None:
    def room(value: str, path: KeyPath) -> None:
        if value not in world.rooms:
            raise doc.error(path, f"no room '{value}' in world '{world.name}'; "
                            f"{suggest(value, world.rooms)}")

    try:
        STRATEGIES.get(spec.assignment.strategy)
    except UnknownEntry as exc:
        raise doc.error(("assignment", "strategy"), str(exc)) from None
    if spec.scene.movers and not any(s.kind == "corridor" for s in world.spaces.values()):
        raise doc.error(("scene", "movers"), f"world '{world.name}' has no corridors for "
                        "moving obstacles to pace")
    places = {*world.groups, *world.segments}
    for i, entry in enumerate(spec.assignment.search):
        if entry not in places:
            raise doc.error(("assignment", "search", i),
                            f"'{entry}' is neither a building, a group of areas nor a segment; "
                            f"{suggest(entry, places)}")
    for room_id in spec.rooms.set:
        room(room_id, ("rooms", "set", room_id))
    if spec.target.room is not None:
        room(spec.target.room, ("target", "room"))
        if spec.target.position is not None and not world.rooms[spec.target.room].box.contains(
                spec.target.position):
            raise doc.error(("target", "position"),
                            f"{list(spec.target.position)} is not inside room {spec.target.room}")
    elif spec.target.position is not None:
        raise doc.error(("target", "position"), "a target position needs target.room as well")
    avatar = spec.target.avatar
    if avatar.tied_to_chair and avatar.activity not in (None, "sitting"):
        raise doc.error(("target", "avatar", "tied_to_chair"), "only a sitting avatar is tied "
                        f"to a chair (activity: {avatar.activity})")
    kinds = {m.id: m.kind for m in spec.team}
    points: dict[tuple[tuple[float, ...], str], KeyPath] = {}  # where a robot stands or goes
    for i, member in enumerate(spec.team):
        for name in member.sensor_set.plugins:
            if name not in SENSORS:
                known = list(SENSORS)
                raise doc.error(("team", i, "sensors", "plugins", name), f"no sensor '{name}'; "
                                + (suggest(name, known) if known else "none is registered "
                                   "(astralis_des.plugins.SENSORS)"))
        if isinstance(member.start, str):
            room(member.start, ("team", i, "start"))
        else:
            points.setdefault((tuple(member.start), member.kind), ("team", i, "start"))
    for i, event in enumerate(spec.timeline):
        robot = getattr(event, "robot", None)
        if robot is not None and robot not in kinds:
            raise doc.error(("timeline", i, "robot"),
                            f"no robot '{robot}' in the team; {suggest(robot, kinds)}")
        event_room = getattr(event, "room", None)
        if event_room is not None:
            room(event_room, ("timeline", i, "room"))
        if isinstance(event, CommandEvent) and (kinds[event.robot], event.action) not in ACTIONS:
            kind = kinds[event.robot]
            raise doc.error(("timeline", i, "action"),
                            f"a {kind} has no action '{event.action}'; "
                            f"{suggest(event.action, actions_for(kind))}")
        if isinstance(event, CommandEvent):
            for name in event.params:
                try:
                    check_params(kinds[event.robot], event.action,
                                 {name: event.params[name]})
                except ValueError as exc:
                    raise doc.error(("timeline", i, "params", name), str(exc)) from None
            goal = _goal(event)
            if goal is not None:
                points.setdefault((goal, kinds[event.robot]), ("timeline", i, "params"))
    for (point, who), where in points.items():  # each point and kind once, in file order
        refused = problem(world, point, who)
        if refused is not None:
            raise doc.error(where, refused)
    if spec.timeline and max(e.at for e in spec.timeline) > spec.time_limit:
        late = max(range(len(spec.timeline)), key=lambda k: spec.timeline[k].at)
        raise doc.error(("timeline", late, "at"), "this event comes after time_limit")


def _goal(event: CommandEvent) -> tuple[float, ...] | None:
    """The point a ``move`` command names (params x, y and z), if it names one."""
    if event.action != "move" or event.room is not None or not {"x", "y"} <= set(event.params):
        return None
    x, y, z = (event.params.get(k, 0.0) for k in ("x", "y", "z"))
    return (float(x), float(y), float(z))
