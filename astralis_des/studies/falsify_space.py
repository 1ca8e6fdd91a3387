"""What ``astralis falsify`` searches: what a mission's seed would draw, as parameters.

    target:   {rooms: [A.1.1.1, ...], place: true, avatar: [activity, height]}
    rooms:    {rooms: [...], risk: {low: 0, high: 1}, messiness: {low: 0, high: 1},
               sound: false}                                      # each room's properties
    faults:   {robots: [uav1, ugv1], at: {low: 0, high: 400}, none: true}
    movers:   {low: 0, high: 4}                                   # moving obstacles
    starts:   {choices: 8, spacing: 4}                            # free spots near each start
    comm_range: {low: 5, high: 100, log: true}                    # CBBA's
    seed:     {low: 0, high: 1000}                                # clutter and sensing draws

Every section may be ``false`` (the mission's own value is kept) and every key left out
(the mission's own range: the searched rooms, Table II's attributes, risk and messiness on
[0, 1], a fault of any member before the base mission ends, ...). Sounds and the target's
colour, gender and tie to a chair change nothing a run does (the replay shows them): they are
left to the seed unless named (``sound: [minimal, moderate, loud]``, ``avatar: true``).
A trial's parameters become
mission changes (:meth:`Space.changes`): every drawn value set explicitly, so the trial is a
complete mission file. The target's room takes its risk, messiness and sound from parameters
of its own (``target.risk``, ...), not from its ``room.ID.*`` ones: what hides a target in
clutter is then one thing to learn, whichever room it is in.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator

from astralis_des.errors import suggest
from astralis_des.kinds import TARGET_HEIGHT
from astralis_des.mission.draws import AVATAR_VALUES
from astralis_des.mission.loader import Mission
from astralis_des.mission.spec import Sound, Strict
from astralis_des.studies.tune_spec import Interval
from astralis_des.validation import validate
from astralis_des.world.placement import shown
from astralis_des.world.spots import free_spots
from astralis_des.yamlio import KeyPath, LocatedYaml, load_yaml

NO_FAULT = "none"
PLACE_GRID = 0.1  # m: the free floor's cells the target's place snaps to
LAYING = (1.8, 0.6)  # m: the footprint of a laying target (Scene's), else a standing one
STANDING = (0.5, 0.5)
ROOM_PROPS = ("risk", "messiness", "sound")
# Table II's attributes that change what a run does (a laying target's footprint, a patrolling
# one's walk and its height); colour, gender and the tie to a chair are only shown
AvatarKey = Literal["activity", "color", "gender", "height", "tied_to_chair"]
SHAPING: tuple[AvatarKey, ...] = ("activity", "height")
COMM_RANGE = (5.0, 100.0)  # m: CBBA's range searched when the space file says nothing


class IntRange(Strict):
    low: int = Field(ge=0)
    high: int = Field(ge=0)

    @model_validator(mode="after")
    def _ordered(self) -> IntRange:
        if not self.low < self.high:
            raise ValueError(f"empty or inverted range: low {self.low} must be below high "
                             f"{self.high}")
        return self


class TargetSpace(Strict):
    rooms: list[str] | None = Field(None, min_length=1,
                                    description="default: the mission's searched rooms")
    place: bool = Field(True, description="where in its room (a free spot)")
    avatar: tuple[AvatarKey, ...] | bool = Field(
        SHAPING, description="Table II's attributes searched (true: all of them); by "
        "default those that change a run: the posture and, for a patrolling target, height")


class RoomsSpace(Strict):
    rooms: list[str] | None = Field(None, min_length=1,
                                    description="default: the mission's searched rooms")
    risk: Interval | Literal[False] = Interval(low=0.0, high=1.0)
    messiness: Interval | Literal[False] = Interval(low=0.0, high=1.0)
    sound: tuple[Sound, ...] | Literal[False] = False  # changes nothing a run does (shown)


class FaultSpace(Strict):
    robots: list[str] | None = Field(None, description="default: every member")
    at: Interval | None = Field(None, description="s; default: until the base mission ends")
    none: bool = Field(True, description="no fault at all is one of the choices")


class StartSpace(Strict):
    robots: list[str] | None = Field(None, description="default: every member with a point")
    choices: int = Field(8, ge=1, le=100, description="free spots, the given start first")
    spacing: float = Field(4.0, gt=0, le=100, description="m between the spots")


class SpaceSpec(Strict):
    target: TargetSpace | Literal[False] = Field(default_factory=TargetSpace)
    rooms: RoomsSpace | Literal[False] = Field(default_factory=RoomsSpace)
    faults: FaultSpace | Literal[False] = Field(default_factory=FaultSpace)
    movers: IntRange | Literal[False] | None = None  # None: 0 to 4 where there are corridors
    starts: StartSpace | Literal[False] = Field(default_factory=StartSpace)
    comm_range: Interval | Literal[False] | None = None  # None: searched when a strategy is cbba
    seed: IntRange | Literal[False] = False


@dataclass(frozen=True)
class Dim:
    """One parameter: choices, or a number range (``integer``, ``log``)."""

    choices: tuple[Any, ...] | None = None
    low: float = 0.0
    high: float = 1.0
    integer: bool = False
    log: bool = False

    def distribution(self) -> Any:
        from optuna.distributions import (
            CategoricalDistribution,
            FloatDistribution,
            IntDistribution,
        )

        if self.choices is not None:
            return CategoricalDistribution(self.choices)
        if self.integer:
            return IntDistribution(int(self.low), int(self.high))
        return FloatDistribution(self.low, self.high, log=self.log)


@dataclass(frozen=True)
class Space:
    """The parameters of a mission's scenario space, and how a trial's values set them."""

    mission: Mission
    dims: dict[str, Dim]
    starts: dict[str, list[list[float]]]  # member id -> its choices of start points

    def distributions(self) -> dict[str, Any]:
        return {name: dim.distribution() for name, dim in self.dims.items()}

    def changes(self, params: dict[str, Any]) -> dict[str, Any]:
        """The mission's top-level fields with the trial's values set (plain JSON): what
        ``Mission.with_changes`` takes and a mission file holds."""
        spec = self.mission.spec
        out: dict[str, Any] = {}
        if "seed" in params:
            out["seed"] = int(params["seed"])
        out["target"] = self._target(params)
        rooms = spec.rooms.model_dump(mode="json", exclude_none=True)
        for name, value in params.items():
            if name.startswith("room."):
                room, _, prop = name[len("room."):].rpartition(".")
                rooms["set"].setdefault(room, {})[prop] = _rounded(value)
        where = out["target"].get("room")
        for prop in ROOM_PROPS:  # the target's room's own: one parameter whatever the room
            if f"target.{prop}" in params and where is not None:
                rooms["set"].setdefault(where, {})[prop] = _rounded(params[f"target.{prop}"])
        out["rooms"] = rooms
        timeline = [e.model_dump(mode="json") for e in spec.timeline]
        robot = params.get("fault.robot", NO_FAULT)
        if robot != NO_FAULT:
            timeline.append({"at": _rounded(params["fault.at"], 1), "event": "fault",
                             "robot": robot, "reason": "falsify"})
            timeline.sort(key=lambda e: e["at"])  # stable: the mission's own first at a tie
        out["timeline"] = timeline
        scene = spec.scene.model_dump(mode="json", exclude_none=True)
        if "movers" in params:
            scene["movers"] = int(params["movers"])
        out["scene"] = scene
        team = [m.model_dump(mode="json", exclude_unset=True) for m in spec.team]
        for member in team:
            key = f"start.{member['id']}"
            if key in params:
                member["start"] = self.starts[member["id"]][int(params[key])]
        out["team"] = team
        assignment = spec.assignment.model_dump(mode="json", exclude_unset=True)
        if "comm_range" in params:
            options = dict(assignment.get("options", {}))
            options["comm_range"] = _rounded(params["comm_range"], 2)
            assignment["options"] = options
        out["assignment"] = assignment
        return out

    def _target(self, params: dict[str, Any]) -> dict[str, Any]:
        target = self.mission.spec.target.model_dump(mode="json", exclude_none=True)
        avatar = dict(target.get("avatar", {}))
        for key in AVATAR_VALUES:
            if f"target.{key}" in params:
                avatar[key] = params[f"target.{key}"]
        if avatar.get("tied_to_chair") and avatar.get("activity") != "sitting":
            avatar["tied_to_chair"] = False  # only a sitting avatar is (Table II's rule)
        target["avatar"] = avatar
        if "target.room" in params:
            target["room"] = params["target.room"]
            target.pop("position", None)
        if "target.x" in params:
            footprint = LAYING if avatar.get("activity") == "laying" else STANDING
            target["position"] = target_spot(self.mission, target["room"],
                                             (params["target.x"], params["target.y"]),
                                             footprint)
        return target


def _rounded(value: Any, digits: int = 3) -> Any:
    """A drawn number as a file shows it (and as the trial runs it)."""
    return round(float(value), digits) if isinstance(value, float) else value


def target_spot(mission: Mission, room_id: str, where: tuple[float, float],
                footprint: tuple[float, float]) -> list[float]:
    """The point of ``room_id``'s free floor nearest the fractions ``where`` of its box at
    which the target's footprint lies wholly on free floor (its furniture is moved aside)."""
    from scipy.ndimage import binary_erosion

    from astralis_des.world.freespace import room_free_space

    room = mission.world.rooms[room_id]
    space = room_free_space(mission.world, room_id, cell=PLACE_GRID)
    kernel = np.ones([max(1, int(np.ceil(f / space.cell))) | 1 for f in footprint], bool)
    fits = binary_erosion(space.free, kernel, border_value=0)
    cells = np.argwhere(fits if fits.any() else space.free)
    lo, hi = np.array(room.box.lo[:2]), np.array(room.box.hi[:2])
    if not len(cells):
        x, y = (lo + hi) / 2
    else:
        centres = np.array(space.origin) + (cells + 0.5) * space.cell
        goal = lo + np.clip(np.asarray(where, float), 0.0, 1.0) * (hi - lo)
        d = np.round(np.linalg.norm(centres - goal, axis=1), 9)
        x, y = centres[np.lexsort((centres[:, 1], centres[:, 0], d))[0]]
    return [round(float(x), 2), round(float(y), 2), round(room.box.lo[2] + TARGET_HEIGHT, 3)]


# -- the space of a mission ------------------------------------------------------------------
def load_space(path: str | Path | None, mission: Mission, *, strategies: list[str],
               fault_until: float) -> Space:
    """The space file's parameters (or the mission's own ranges, without a file); a problem
    names the file, line and key. ``fault_until``: the end of the fault window by default
    (the base mission's end)."""
    doc = load_yaml(path) if path is not None else LocatedYaml({}, {}, Path("<space>"))
    if doc.data is None:
        doc = LocatedYaml({}, {}, doc.file)
    spec = validate(SpaceSpec, doc)
    return build_space(spec, doc, mission, strategies, fault_until)


def build_space(spec: SpaceSpec, doc: LocatedYaml, mission: Mission, strategies: list[str],
                fault_until: float) -> Space:
    world = mission.world
    given = mission.spec
    ids = [m.id for m in given.team]
    dims: dict[str, Dim] = {}
    starts: dict[str, list[list[float]]] = {}

    def rooms_at(path: KeyPath, rooms: list[str] | None) -> list[str]:
        for i, room in enumerate(rooms or []):
            if room not in world.rooms:
                raise doc.error((*path, i), f"no room '{room}' in world '{world.name}'; "
                                f"{suggest(room, world.rooms)}")
        return rooms or mission.searched_rooms() or sorted(world.rooms)

    def robots_at(path: KeyPath, robots: list[str] | None) -> list[str]:
        for i, robot in enumerate(robots or []):
            if robot not in ids:
                raise doc.error((*path, i), f"no member '{robot}' in the team; "
                                f"{suggest(robot, ids)}")
        return ids if robots is None else robots

    if spec.seed is not False:
        dims["seed"] = Dim(low=spec.seed.low, high=spec.seed.high, integer=True)
    if spec.target is not False:
        target = spec.target
        if given.target.room is None or target.rooms is not None:
            dims["target.room"] = Dim(tuple(rooms_at(("target", "rooms"), target.rooms)))
        if target.place and given.target.position is None:
            dims["target.x"] = Dim()
            dims["target.y"] = Dim()
        searched = (list(AVATAR_VALUES) if target.avatar is True else
                    [] if target.avatar is False else target.avatar)
        fixed = given.target.avatar.model_dump(exclude_none=True)
        if fixed.get("tied_to_chair"):  # tied to a chair: sitting (the loader's rule)
            fixed["activity"] = "sitting"
        for key, values in AVATAR_VALUES.items():
            if key in searched and key not in fixed:
                dims[f"target.{key}"] = Dim(tuple(values))
    if spec.rooms is not False:
        props = spec.rooms
        if props.sound == ():
            raise doc.error(("rooms", "sound"), "no sounds: give at least one, or false to "
                            "keep the mission's")
        ranges = {}
        for prop in ROOM_PROPS:
            bound = getattr(props, prop)
            if isinstance(bound, Interval):
                _within(doc, ("rooms", prop), bound, 0.0, 1.0)
                ranges[prop] = Dim(low=bound.low, high=bound.high)
            elif bound is not False:
                ranges[prop] = Dim(tuple(dict.fromkeys(bound)))
        if spec.target is not False:  # the target's room: its own parameters, so that what
            # hides a target is learnt once, not once per room it may be in
            dims.update({f"target.{prop}": dim for prop, dim in ranges.items()})
        for room in rooms_at(("rooms", "rooms"), props.rooms):
            dims.update({f"room.{room}.{prop}": dim for prop, dim in ranges.items()})
    if spec.faults is not False:
        robots = robots_at(("faults", "robots"), spec.faults.robots)
        choices = ([NO_FAULT] if spec.faults.none else []) + robots
        if len(choices) > 1 or (choices and choices[0] != NO_FAULT):
            at = spec.faults.at or Interval(low=0.0, high=max(fault_until, 1.0))
            _within(doc, ("faults", "at"), at, 0.0, given.time_limit)
            dims["fault.robot"] = Dim(tuple(choices))
            dims["fault.at"] = Dim(low=at.low, high=at.high)
    corridors = any(s.kind == "corridor" for s in world.spaces.values())
    if spec.movers is None and corridors:
        dims["movers"] = Dim(low=0, high=max(4, 2 * given.scene.movers), integer=True)
    elif isinstance(spec.movers, IntRange):
        if not corridors:
            raise doc.error(("movers",), f"world '{world.name}' has no corridors for moving "
                            "obstacles to pace")
        _within(doc, ("movers",), spec.movers, 0, 100)
        dims["movers"] = Dim(low=spec.movers.low, high=spec.movers.high, integer=True)
    if spec.starts is not False:
        for member in given.team:
            if member.id not in robots_at(("starts", "robots"), spec.starts.robots) or \
                    isinstance(member.start, str):
                continue
            spots = _starts(mission, member.kind, member.start, spec.starts)
            if len(spots) > 1:
                starts[member.id] = spots
                dims[f"start.{member.id}"] = Dim(tuple(range(len(spots))))
    comm = spec.comm_range
    if comm is None and "cbba" in strategies:
        comm = Interval(low=COMM_RANGE[0], high=COMM_RANGE[1], log=True)
    if isinstance(comm, Interval):
        _within(doc, ("comm_range",), comm, 1e-3, 1e6)
        dims["comm_range"] = Dim(low=comm.low, high=comm.high, log=comm.log)
    if not dims:
        raise doc.error((), "the space has no parameter to search: every section is false or "
                        "fixed by the mission")
    return Space(mission, dims, starts)


def _within(doc: LocatedYaml, path: KeyPath, bound: Interval | IntRange, low: float,
            high: float) -> None:
    if bound.low < low or bound.high > high:
        raise doc.error(path, f"the range {bound.low:g} to {bound.high:g} goes beyond "
                        f"{low:g} to {high:g}")


def _starts(mission: Mission, kind: str, start: tuple[float, ...],
            space: StartSpace) -> list[list[float]]:
    """The given start, then the free spots nearest it (indoors if it is), as file points."""
    point = [float(v) for v in start]
    place = mission.world.router.place_of(np.array(point))
    spots = free_spots(mission.world, [kind], near=(point[0], point[1]),
                       count=space.choices, spacing=space.spacing,
                       where="outdoor" if place == "outdoor" else "indoor")
    out = [point]
    for spot in spots:
        p = [float(v) for v in spot.point]
        if abs(p[2] - point[2]) < 0.5 and p not in out and len(out) < space.choices:
            out.append(p)
    return out


def describe(space: Space) -> list[tuple[str, str]]:
    """Each parameter and its range, as the report lists them."""
    rows = []
    for name, dim in space.dims.items():
        if name.startswith("start."):
            text = "; ".join(shown(tuple(p)) for p in space.starts[name[len("start."):]])
        elif dim.choices is not None:
            text = ", ".join(map(str, dim.choices))
        else:
            text = f"{dim.low:g} to {dim.high:g}" + (" (log)" if dim.log else "")
        rows.append((name, text))
    return rows
