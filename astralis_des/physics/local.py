"""The local layer: robots in physics avoid what moves (other robots, patrolling avatars,
moving obstacles, the lift), from what each knows of the others' positions, at ``RATE``.

Only bodies in the same free space count (a straight line between the two crosses no wall):
an avatar in the next room is no reason to move. The rules, as people keep to in corridors:
- keep right: something coming head-on in or near the robot's lane makes it shift to its
  right, by as much as keeps the whole path ahead (``PATH_AHEAD``) clear of walls and
  furniture; never in a doorway or with one on the path ahead, where it keeps to its path;
- hold: something ahead on the robot's route, closer than its stopping range, makes it wait
  (its reference stops). Head-on between two robots only the lower-priority one holds (team
  order); scripted movers, the lift and robots standing still never yield, so robots do; and
  a robot keeps its distance behind one going its way;
- doorways are taken in turn: a robot with a doorway on its path ahead waits while another
  body is in it, or while a robot of higher priority is about to cross it; a robot waiting
  for another that comes its way steps off that one's route, where there is room;
- step aside: something standing still in the lane is passed on the side with room;
- a UAV on a walker's (a person's, an avatar's) collision course, or with one standing on its
  route, climbs over it (:mod:`.climb`);
- a robot standing idle in another's way (in its lane, in the doorway it waits for, on its
  goal) is asked to make way: it moves to the nearest free spot off the other's path
  (:mod:`.make_way`); a goal a body stands on counts as reached from farther.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.physics.climb import MOVER_AHEAD, Climber
from astralis_des.physics.courses import Body, on_route
from astralis_des.physics.drivers import SAMPLE
from astralis_des.world.geometry import FloatArray, segments_hit_boxes

if TYPE_CHECKING:
    from astralis_des.physics.drivers import Driver
    from astralis_des.physics.engine import Engine

PASS_RANGE = 5.0  # m: closer than this, head-on, both keep right
BRAKING = 1.0  # s: the stopping range grows by this times the robot's speed
SHIFT = 0.7  # m to the right at most
STOP_RANGE = 0.8  # m between bodies' edges ahead: hold
LANE_MARGIN = 0.15  # m added to the two radii to decide "in my lane"
STILL_RANK = 10_000  # movers, the lift, and robots not moving: everyone yields to them
NEAR = 6.0  # m: movers farther than this from every moving robot need not move in physics
RATE = 5.0  # Hz: how often the layer decides (a UAV flies 0.3 m in between)
PATH_AHEAD = 3.0  # m of its path that a shifted robot must keep clear
DOOR_IN = 0.6  # m off a doorway's wall line (and within its width) is in the doorway
DOOR_HALF_WIDTH = 0.7  # m along the wall from a doorway's centre that count as in it
DOOR_ON_PATH = 0.4  # m: a path passing this near a doorway's centre goes through it
DOOR_BUSY = 1.0  # m: a body this near a doorway is in it; the others wait
GOAL_TAKEN = 2.8  # m: a goal another body stands still on is reached this near
SHARES = (1.0, 2 / 3, 1 / 3)  # of a keep-right shift, tried in turn
ROUND_MARGIN = 0.05  # m beyond the lane a robot stepping round a standing body keeps
MAKE_WAY_PATH = 6.0  # m of the asking robot's path that a robot making way keeps off

# robot standing in another's way -> (the robot asking it to make way, that one's path ahead)
Requests = dict[str, tuple[str, FloatArray]]


class LocalLayer:
    def __init__(self, cosim: Engine, order: list[str]) -> None:
        self.cosim = cosim
        self.rank = {rid: len(order) - i for i, rid in enumerate(order)}
        self.holds = 0  # how many times a robot was held (for tests and benchmarks)
        self.shifts = 0  # how many times a robot was shifted aside
        self.climbs = 0  # how many times a UAV climbed over a walker
        self.near: list[int] = []  # movers within NEAR of a moving robot: the ones to move
        self._paths: dict[str, FloatArray] = {}  # where each moving robot will be, xy
        self.climber = Climber(cosim.fits)
        self.solids = cosim.world.solid_array
        self.doors = cosim.world.doorways

    def bodies(self, t: float) -> list[Body]:
        found = []
        for rid, driver in self.cosim.drivers.items():
            robot = self.cosim.robots[rid]
            here = driver.position()
            kind = KIND_DEFAULTS[robot.kind]
            low, high = kind.band
            active = rid in self.cosim.active
            velocity = driver.heading_vector() if active and not driver.held else np.zeros(2)
            # a robot that is not moving cannot yield: it ranks with the movers
            rank = self.rank[rid] if active else STILL_RANK
            course = driver.course_z() if active else None
            course = here[2] if course is None else course
            found.append(Body(rid, robot.kind, here[:2], velocity,
                              (here[2] + low, here[2] + high), kind.passes_by, rank,
                              (course + low, course + high), driver.shift,
                              kind.half_width))
        for mover, _ in self.cosim.movers:
            here = mover.position_at(t)
            ahead = mover.position_at(t + 0.5)
            half = mover.size[2] / 2
            band = (here[2] - half, here[2] + half)
            found.append(Body(mover.id, mover.kind, here[:2], (ahead[:2] - here[:2]) / 0.5,
                              band, max(mover.size[0], mover.size[1]) / 2, STILL_RANK, band))
        for lift in self.cosim.lifts:
            if lift.moving:
                found.append(Body(f"lift:{lift.building}", "lift", lift.centre, np.zeros(2),
                                  lift.z_range, lift.radius, STILL_RANK, lift.z_range))
        return found

    def update(self, t: float) -> Requests:
        """Decide, for each moving robot, whether to hold and how far to shift aside (set on
        its driver); return the robots standing in another's way, each with who asks it to
        make way and that one's path ahead (the first to ask, in team order)."""
        requests: Requests = {}
        if not self.cosim.active:
            self.near = []
            return requests
        bodies = self.bodies(t)
        where = np.array([b.xy for b in bodies])
        robots = len(self.cosim.drivers)
        moving = np.array([b.xy for b in bodies[:robots] if b.name in self.cosim.active])
        movers = where[robots:robots + len(self.cosim.movers)]
        gaps = np.linalg.norm(movers[:, None, :] - moving[None, :, :], axis=2)
        self.near = [int(i) for i in np.flatnonzero((gaps < NEAR).any(axis=1))]
        by_name = {b.name: b for b in bodies}
        seen = {rid: self._others(by_name[rid], bodies, where) for rid in self.cosim.active}
        for rid, others in seen.items():
            if not others:  # nothing in sight: nothing to avoid (the usual case, and cheap)
                driver = self.cosim.drivers[rid]
                driver.arrive_within = 0.2
                driver.avoid(False, np.zeros(2))
        if not any(seen.values()):  # no one's path ahead is asked for
            return requests
        paths = {rid: self.cosim.drivers[rid].path_ahead(PATH_AHEAD) for rid in self.cosim.active}
        doors = _Doors(self, by_name, paths)
        self._paths = {rid: path[:, :2] + by_name[rid].offset for rid, path in paths.items()}
        for i in self.near:  # where the movers near a robot will walk: scripted, so known
            mover = self.cosim.movers[i][0]
            self._paths[mover.id] = mover.positions_at(t + MOVER_AHEAD)[:, :2]
        for rid, others in seen.items():
            if others:
                self._decide_for(rid, by_name[rid], others, paths[rid], doors, requests)
        return requests

    def _others(self, me: Body, bodies: list[Body], where: FloatArray) -> list[Body]:
        """The bodies near ``me`` (``where``: theirs), at heights it spans, in sight of it."""
        near = np.linalg.norm(where - me.xy, axis=1) < PASS_RANGE + 1.0
        low, high = me.base_z[0] - 0.3, max(me.z[1], me.base_z[1]) + 0.3
        return self._in_sight(me, [b for b, c in zip(bodies, near, strict=True)
                                   if c and b.name != me.name
                                   and max(b.z[1], b.base_z[1]) >= low
                                   and min(b.z[0], b.base_z[0]) <= high])

    def _decide_for(self, rid: str, me: Body, others: list[Body], ahead: FloatArray,
                    doors: _Doors, requests: Requests) -> None:
        driver = self.cosim.drivers[rid]
        direction = driver.heading_vector()
        speed = float(np.linalg.norm(direction))
        if speed < 1e-6:  # at its point: a UAV still rises over a walker coming at it
            here = me.xy[None, :]
            climb = self.climber.need(me, others, np.zeros(2), here, here,
                                      not self._by_doorway(me.xy, me.base_z[0]),
                                      self._paths)[0] if KIND_DEFAULTS[me.kind].flies else 0.0
            driver.avoid(False, np.zeros(2), climb)
            return
        forward = direction / speed
        right = np.array([forward[1], -forward[0]])
        route = ahead[:, :2] + me.offset
        if len(route) < 3:  # at the end of its path: the way it is headed
            route = me.xy + forward * np.arange(0.0, PATH_AHEAD, SAMPLE)[:, None]
        heights = ahead[:, 2] if KIND_DEFAULTS[me.kind].flies and len(ahead) >= 3 else None
        hold, shift, aside, blockers = self._decide(me, others, forward, right, speed, route,
                                                    heights)
        door = doors[rid]
        in_door = self._door_taken(rid, me, door, others, doors) if door is not None else None
        if in_door is not None:
            hold = True
            blockers.append(in_door)
        occupant = self._goal_taken(driver, me, others)
        driver.arrive_within = GOAL_TAKEN if occupant is not None else 0.2
        pressing = [b for b in others if b.name in driver.blocked_by]
        for other in [*blockers, *([occupant] if occupant else []), *pressing]:
            if other.name in self.cosim.drivers and other.name not in self.cosim.active and \
                    self.cosim.may_ask(other.name):
                requests.setdefault(other.name, (rid, driver.path_ahead(MAKE_WAY_PATH)))
        in_doorway = self._by_doorway(me.xy, me.base_z[0])
        open_space = door is None and not in_doorway
        climb, coming = self.climber.need(me, others, direction, route, ahead[:, :2] + me.offset,
                                          open_space, self._paths, _lowest(me, ahead)) \
            if KIND_DEFAULTS[me.kind].flies else (0.0, [])
        hold = hold or bool(coming)
        if shift.any() and open_space:
            shift = self._clear_shift(rid, ahead, shift, (1.0,) if aside else SHARES)
        else:
            shift = np.zeros(2)
        if hold:  # waiting for a robot or a walker that comes this way: out of its way too
            shift = self._yield(me, [*blockers, *coming], ahead, shift)
        self.holds += hold
        self.shifts += bool(shift.any())
        self.climbs += bool(climb)
        driver.avoid(hold, shift, climb)

    def _decide(self, me: Body, others: list[Body], forward: FloatArray, right: FloatArray,
                speed: float, route: FloatArray, heights: FloatArray | None = None
                ) -> tuple[bool, FloatArray, bool, list[Body]]:
        """Hold or not; the shift off the path (a vector in the plane: keep right, or step
        round something standing still); whether that shift steps round something (all of
        it, or no use); and the bodies the robot holds for. ``route``: where the robot will
        be over the next metres (its path ahead, as shifted now), ``SAMPLE`` apart; a UAV's
        ``heights`` along it: a body it would pass over where its way meets it (a person
        beyond a door it ducks through under the lintel) is no reason to hold."""
        hold, shift, aside = False, np.zeros(2), False
        blockers: list[Body] = []
        stop = STOP_RANGE + BRAKING * speed
        path = route - me.offset  # the path itself, unshifted
        for other in others:
            if other.z[1] < me.z[0] or other.z[0] > me.z[1]:
                continue  # above or below it (a UAV over the UGV)
            rel = other.xy - me.xy
            along, across = float(rel @ forward), float(rel @ right)
            gap = math.hypot(along, across) - me.radius - other.radius
            lane = me.half_width + other.half_width + LANE_MARGIN
            if gap > PASS_RANGE:
                continue
            reach, off_route = on_route(route, other.xy, other.velocity)
            if heights is not None and gap > 0.0:
                there = float(heights[min(round(reach / SAMPLE), len(heights) - 1)])
                if other.z[1] < there + KIND_DEFAULTS[me.kind].band[0]:
                    continue  # under its way where it gets there
            if along > 0 and off_route < lane + SHIFT:
                if float(other.velocity @ forward) < -0.05:  # coming towards us: keep right
                    if not aside and abs(across + float(me.offset @ right)) < lane + SHIFT:
                        shift = right * SHIFT
                elif float(np.linalg.norm(other.velocity)) < 0.05:
                    side = _round(path, other.xy, lane)  # standing on our way
                    if side is not None and float(np.linalg.norm(side)) > \
                            float(np.linalg.norm(shift)):
                        shift, aside = side, True
            ahead = along > 0 and reach - me.radius - other.radius < stop and off_route < lane
            # hold for a body of higher priority ahead, and for any ahead going our way (it
            # is followed at a distance, not pushed)
            if ahead and (other.rank > me.rank or float(other.velocity @ forward) > 0.05):
                hold = True
                blockers.append(other)
        return hold, shift, aside, blockers

    # -- the free space around a robot ------------------------------------------------------
    def _in_sight(self, me: Body, others: list[Body]) -> list[Body]:
        """The bodies in the same free space as ``me``: the line between the two (at a height
        both span) crosses no wall or slab. The lift counts whatever is between."""
        if not others:
            return others
        z = [(max(me.z[0], o.z[0]) + min(me.z[1], o.z[1])) / 2 for o in others]
        a = np.column_stack([np.repeat(me.xy[None, :], len(others), axis=0), z])
        b = np.column_stack([np.array([o.xy for o in others]), z])
        hidden = segments_hit_boxes(a, b, self.solids)
        return [o for o, h in zip(others, hidden, strict=True) if o.kind == "lift" or not h]

    def _clear_shift(self, rid: str, ahead: FloatArray, shift: FloatArray,
                     shares: tuple[float, ...]) -> FloatArray:
        """The largest share of ``shift`` that keeps robot ``rid``'s path ahead clear, or
        none."""
        points = np.concatenate([ahead + np.array([*(shift * share), 0.0])
                                 for share in shares])  # from the robot's unshifted place on
        fits = self.cosim.fits(rid, points).reshape(len(shares), len(ahead)).all(axis=1)
        return shift * shares[int(np.argmax(fits))] if fits.any() else np.zeros(2)

    def _yield(self, me: Body, blockers: list[Body], ahead: FloatArray,
               shift: FloatArray) -> FloatArray:
        """The shift that takes a robot waiting for others off the routes of those coming
        its way (if the spot is free), else ``shift``."""
        best = shift
        for other in blockers:
            route = self._paths.get(other.name)
            if route is None or float(np.linalg.norm(other.velocity)) < 0.05:
                continue
            clear = me.half_width + other.half_width + LANE_MARGIN
            d = np.linalg.norm(route - me.xy, axis=1)
            i = int(np.argmin(d))
            if d[i] >= clear:
                continue
            if d[i] > 1e-6:
                away = (me.xy - route[i]) / d[i]
            else:  # on the route itself: to its right
                tangent = route[min(i + 1, len(route) - 1)] - route[max(i - 1, 0)]
                away = np.array([tangent[1], -tangent[0]]) / max(float(np.linalg.norm(tangent)),
                                                                 1e-9)
            wanted = me.offset + away * (clear + 0.05 - d[i])
            spot = ahead[:1] + np.array([*wanted, 0.0])
            if self.cosim.fits(me.name, spot).all() and \
                    float(np.linalg.norm(wanted)) > float(np.linalg.norm(best)):
                best = wanted
        return best

    # -- doorways ----------------------------------------------------------------------------
    def _doors_on(self, floor_z: float) -> FloatArray:
        return self.doors[np.abs(self.doors[:, 2] - floor_z) < 1.0] if len(self.doors) else \
            self.doors

    def _by_doorway(self, xy: FloatArray, low: float) -> bool:
        """Is ``xy`` in a doorway: within ``DOOR_IN`` of its wall's line, and within the
        door's width (and a little) of its centre along the wall?"""
        floor = self.cosim.world.floor_below((float(xy[0]), float(xy[1]), max(low, 0.0)))
        doors = self._doors_on(floor)
        if not len(doors):
            return False
        normal = doors[:, 3].astype(int)
        rows = np.arange(len(doors))
        off_wall = np.abs(xy[normal] - doors[rows, normal])
        along_wall = np.abs(xy[1 - normal] - doors[rows, 1 - normal])
        return bool(np.any((off_wall < DOOR_IN) & (along_wall < DOOR_HALF_WIDTH)))

    def _door_ahead(self, me: Body, ahead: FloatArray) -> int | None:
        """The doorway the path ahead goes through first (an index into ``doors``)."""
        if not len(self.doors) or not len(ahead):
            return None
        d = np.linalg.norm(ahead[:, None, :2] - self.doors[None, :, :2], axis=2)
        floor = self.cosim.world.floor_below((*ahead[0, :2], max(me.base_z[0], 0.0)))
        d[:, np.abs(self.doors[:, 2] - floor) > 1.0] = np.inf
        hit = np.argwhere(d < DOOR_ON_PATH)
        return int(hit[0, 1]) if len(hit) else None

    def _door_taken(self, rid: str, me: Body, door: int, others: list[Body],
                    doors: _Doors) -> Body | None:
        """Whom must this robot wait for at the doorway on its path? No one once it is in
        it."""
        centre = self.doors[door, :2]
        if float(np.linalg.norm(me.xy - centre)) < DOOR_BUSY:
            return None
        for other in others:  # by their courses: a UAV climbing over a walker still counts
            if other.kind == "lift" or other.base_z[1] < me.base_z[0] - 0.3 or \
                    other.base_z[0] > me.base_z[1] + 0.3:
                continue
            if float(np.linalg.norm(other.xy - centre)) < DOOR_BUSY:
                return other  # someone is in the doorway
            if other.name in self.cosim.active and doors.get(other.name) == door and \
                    other.rank > me.rank and \
                    other.rank != STILL_RANK:
                return other  # a robot of higher priority is about to go through
        return None

    # -- goals and walkers ----------------------------------------------------------------
    def _goal_taken(self, driver: Driver, me: Body, others: list[Body]) -> Body | None:
        """The body standing still on this robot's goal, if any."""
        goal = driver.goal_point()
        low, high = KIND_DEFAULTS[me.kind].band
        for other in others:
            if float(np.linalg.norm(other.velocity)) > 0.05 or other.kind == "lift":
                continue
            if other.z[1] < goal[2] + low or other.z[0] > goal[2] + high:
                continue
            if float(np.linalg.norm(other.xy - goal[:2])) < me.radius + other.radius + 0.1:
                return other
        return None


def _lowest(me: Body, ahead: FloatArray) -> float:
    """The bottom of a UAV's band where its course comes lowest over its path ahead (the
    climb rule takes the lower of this and its band now): coming down from a lifted point
    (over furniture, or where it made way), it must not come down onto a walker."""
    return float(ahead[:, 2].min()) + KIND_DEFAULTS[me.kind].band[0] if len(ahead) \
        else me.base_z[0]


def _round(path: FloatArray, xy: FloatArray, clear: float) -> FloatArray | None:
    """The shift off ``path`` (a vector) that passes a body standing at ``xy`` ``clear`` away
    on the side away from it, measured where the path comes nearest to it; None when the
    path passes it by that far already."""
    d = np.linalg.norm(path - xy, axis=1)
    i = int(np.argmin(d))
    if d[i] >= clear:
        return None
    j = min(i + 1, len(path) - 1)
    tangent = path[j] - path[j - 1] if j > 0 else np.array([1.0, 0.0])
    norm = float(np.linalg.norm(tangent))
    if norm < 1e-9:
        return None
    normal = np.array([tangent[1], -tangent[0]]) / norm
    offset = float((xy - path[i]) @ normal)  # where it stands, across the path
    clear += ROUND_MARGIN  # past the lane's edge, not on it (where the hold test wavers)
    side = offset - clear if offset >= 0 else offset + clear
    return normal * side


class _Doors:
    """The doorway on each moving robot's path ahead, found when first asked for."""

    def __init__(self, layer: LocalLayer, bodies: dict[str, Body],
                 paths: dict[str, FloatArray]) -> None:
        self.layer, self.bodies, self.paths = layer, bodies, paths
        self.found: dict[str, int | None] = {}

    def get(self, rid: str) -> int | None:
        if rid not in self.found:
            path = self.paths.get(rid)
            self.found[rid] = None if path is None else self.layer._door_ahead(
                self.bodies[rid], path)
        return self.found[rid]

    __getitem__ = get
