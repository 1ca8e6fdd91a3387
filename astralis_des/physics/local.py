"""The local layer: robots in physics avoid what moves (other robots, patrolling avatars,
moving obstacles, the lift), from what each knows of the others' positions, at ``RATE``.

Only bodies in the same free space count (a straight line between the two crosses no wall):
an avatar in the next room is no reason to move. The rules, as people keep to in corridors:
- keep right: something coming head-on in or near the robot's lane makes it shift to its
  right, by as much as keeps the whole path ahead (``PATH_AHEAD``) clear of walls and
  furniture; never near a doorway or with one on the path ahead, where it keeps to its path;
- hold: something in the robot's lane, closer than its stopping range, makes it wait (its
  reference stops). Between two robots only the lower-priority one holds (team order);
  scripted movers, the lift and robots standing still never yield, so robots do;
- doorways are taken in turn: a robot with a doorway on its path ahead waits while another
  body is in it, or while a robot of higher priority is about to cross it;
- step aside: something standing still in the lane is passed on the side with room;
- a UAV climbs over a walker (a person or an avatar) on a collision course with it;
- a goal another body stands on counts as reached from farther away.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.world.geometry import FloatArray, segments_hit_boxes

if TYPE_CHECKING:
    from astralis_des.cosim.physics import PhysicsCoSim
    from astralis_des.physics.drivers import Driver

PASS_RANGE = 5.0  # m: closer than this, head-on, both keep right
LOOK_AHEAD = 0.8  # s: where the others will be, for the lane test
BRAKING = 1.0  # s: the stopping range grows by this times the robot's speed
SHIFT = 0.7  # m to the right at most
STOP_RANGE = 0.8  # m between bodies' edges ahead: hold
LANE_MARGIN = 0.15  # m added to the two radii to decide "in my lane"
HEIGHTS = {"uav": (-0.1, 0.1), "ugv": (-0.5, 0.15), "human": (-1.6, 0.15)}  # around the pose
RADII = {"uav": 0.3, "ugv": 0.5, "human": 0.25}
STILL_RANK = 10_000  # movers, the lift, and robots not moving: everyone yields to them
NEAR = 6.0  # m: movers farther than this from every moving robot need not move in physics
RATE = 5.0  # Hz: how often the layer decides (a UAV flies 0.3 m in between)
PATH_AHEAD = 3.0  # m of its path that a shifted robot must keep clear
DOOR_NEAR = 1.2  # m: this near a doorway, or with one this near its path ahead, no shift
DOOR_ON_PATH = 0.4  # m: a path passing this near a doorway's centre goes through it
DOOR_BUSY = 1.0  # m: a body this near a doorway is in it; the others wait
GOAL_TAKEN = 2.8  # m: a goal another body stands still on is reached this near
CLIMB_MARGIN = 0.3  # m a climbing UAV keeps above a walker's head
CLIMB_SOON = 3.0  # s: a walker this close to meeting a UAV makes it climb
WALKERS = ("human", "avatar")


@dataclass
class Body:
    name: str
    kind: str  # a robot kind, or what a mover is (avatar, obstacle), or "lift"
    xy: FloatArray
    velocity: FloatArray  # xy: zero while it holds
    z: tuple[float, float]
    radius: float
    rank: int  # lower yields to higher; movers rank above every robot
    base_z: tuple[float, float] = (0.0, 0.0)  # a UAV's band before any climb


class LocalLayer:
    def __init__(self, cosim: PhysicsCoSim, order: list[str]) -> None:
        self.cosim = cosim
        self.rank = {rid: len(order) - i for i, rid in enumerate(order)}
        self.holds = 0  # how many times a robot was held (for tests and benchmarks)
        self.shifts = 0  # how many times a robot was shifted aside
        self.climbs = 0  # how many times a UAV climbed over a walker
        self.near: list[int] = []  # movers within NEAR of a moving robot: the ones to move
        self.solids = cosim.world.solid_array
        self.doors = cosim.world.doorways

    def bodies(self, t: float) -> list[Body]:
        found = []
        for rid, driver in self.cosim.drivers.items():
            robot = self.cosim.robots[rid]
            here = driver.position()
            low, high = HEIGHTS[robot.kind]
            active = rid in self.cosim.active
            velocity = driver.heading_vector() if active and not driver.held else np.zeros(2)
            # a robot that is not moving cannot yield: it ranks with the movers
            rank = self.rank[rid] if active else STILL_RANK
            course = driver.course_z() if hasattr(driver, "course_z") else here[2]
            found.append(Body(rid, robot.kind, here[:2], velocity,
                              (here[2] + low, here[2] + high), RADII[robot.kind], rank,
                              (course + low, course + high)))
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

    def update(self, t: float) -> None:
        """Decide, for each moving robot, whether to hold and how far to shift aside."""
        if not self.cosim.active:
            self.near = []
            return
        bodies = self.bodies(t)
        where = np.array([b.xy for b in bodies])
        robots = len(self.cosim.drivers)
        moving = np.array([b.xy for b in bodies[:robots] if b.name in self.cosim.active])
        movers = where[robots:robots + len(self.cosim.movers)]
        gaps = np.linalg.norm(movers[:, None, :] - moving[None, :, :], axis=2)
        self.near = [int(i) for i in np.flatnonzero((gaps < NEAR).any(axis=1))]
        by_name = {b.name: b for b in bodies}
        paths = {rid: self.cosim.drivers[rid].path_ahead(PATH_AHEAD) for rid in self.cosim.active}
        doors = {rid: self._door_ahead(by_name[rid], path) for rid, path in paths.items()}
        for rid in self.cosim.active:
            self._decide_for(rid, by_name[rid], bodies, where, paths[rid], doors)

    def _decide_for(self, rid: str, me: Body, bodies: list[Body], where: FloatArray,
                    ahead: FloatArray, doors: dict[str, int | None]) -> None:
        driver = self.cosim.drivers[rid]
        direction = driver.heading_vector()
        speed = float(np.linalg.norm(direction))
        if speed < 1e-6:
            driver.avoid(False, np.zeros(2))
            return
        forward = direction / speed
        right = np.array([forward[1], -forward[0]])
        near = np.linalg.norm(where - me.xy, axis=1) < PASS_RANGE + 1.0
        others = [b for b, c in zip(bodies, near, strict=True)
                  if c and b.name != me.name and self._same_space(me, b)]
        hold, shift = self._decide(me, others, forward, right, speed)
        door = doors[rid]
        if door is not None and self._door_taken(rid, me, door, others, doors):
            hold = True
        driver.arrive_within = GOAL_TAKEN if self._goal_taken(driver, me, others) else 0.2
        open_space = door is None and not self._by_doorway(me.xy, me.base_z[0])
        climb = self._climb(me, others, ahead) if me.kind == "uav" and open_space else 0.0
        if shift and open_space:
            shift = self._clear_shift(me, ahead, right, shift)
        elif shift:
            shift = 0.0
        self.holds += hold
        self.shifts += bool(shift)
        self.climbs += bool(climb)
        driver.avoid(hold, right * shift, climb)

    def _decide(self, me: Body, others: list[Body], forward: FloatArray,
                right: FloatArray, speed: float = 1.0) -> tuple[bool, float]:
        hold, shift = False, 0.0
        for other in others:
            if other.z[1] < me.z[0] or other.z[0] > me.z[1]:
                continue  # above or below it (a UAV over the UGV)
            rel = other.xy - me.xy
            along, across = float(rel @ forward), float(rel @ right)
            gap = math.hypot(along, across) - me.radius - other.radius
            lane = me.radius + other.radius + LANE_MARGIN
            if along <= 0 or gap > PASS_RANGE:
                continue
            if float(other.velocity @ forward) < -0.05:
                if abs(across) < lane + SHIFT:  # it comes towards us, close: keep right
                    shift = max(shift, SHIFT)
            elif float(np.linalg.norm(other.velocity)) < 0.05 and abs(across) < lane:
                # standing in our lane: pass it on the side with more room
                side = across - lane if across >= 0 else across + lane
                shift = side if abs(side) > abs(shift) else shift
            soon = rel + other.velocity * LOOK_AHEAD
            in_lane = abs(across) < lane or (float(soon @ forward) > 0 and
                                             abs(float(soon @ right)) < lane)
            if in_lane and gap < STOP_RANGE + BRAKING * speed and other.rank > me.rank:
                hold = True
        return hold, shift

    # -- the free space around a robot ------------------------------------------------------
    def _same_space(self, me: Body, other: Body) -> bool:
        """Can the two see each other: does the line between them cross no wall or slab?"""
        z = (max(me.z[0], other.z[0]) + min(me.z[1], other.z[1])) / 2
        if other.kind == "lift":
            return True
        a, b = np.array([[*me.xy, z]]), np.array([[*other.xy, z]])
        return not bool(segments_hit_boxes(a, b, self.solids)[0])

    def _clear_shift(self, me: Body, ahead: FloatArray, right: FloatArray,
                     shift: float) -> float:
        """The largest share of ``shift`` that keeps the path ahead clear, or 0."""
        for share in (1.0, 2 / 3, 1 / 3):
            points = np.vstack([np.array([[*me.xy, ahead[0, 2]]]), ahead])
            points[:, :2] += right * (shift * share)
            if self.cosim.fits(me.name, points).all():
                return shift * share
        return 0.0

    # -- doorways ----------------------------------------------------------------------------
    def _doors_on(self, floor_z: float) -> FloatArray:
        return self.doors[np.abs(self.doors[:, 2] - floor_z) < 1.0] if len(self.doors) else \
            self.doors

    def _by_doorway(self, xy: FloatArray, low: float) -> bool:
        floor = self.cosim.world.floor_below((float(xy[0]), float(xy[1]), max(low, 0.0)))
        doors = self._doors_on(floor)
        return bool(len(doors)) and float(np.min(np.linalg.norm(doors[:, :2] - xy, axis=1))) \
            < DOOR_NEAR

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
                    doors: dict[str, int | None]) -> bool:
        """Must this robot wait for the doorway on its path? Not once it is in it."""
        centre = self.doors[door, :2]
        if float(np.linalg.norm(me.xy - centre)) < DOOR_BUSY:
            return False
        for other in others:
            if other.z[1] < me.z[0] or other.z[0] > me.z[1] or other.kind == "lift":
                continue
            if float(np.linalg.norm(other.xy - centre)) < DOOR_BUSY:
                return True  # someone is in the doorway
            if doors.get(other.name) == door and other.rank > me.rank and \
                    other.rank != STILL_RANK:
                return True  # a robot of higher priority is about to go through
        return False

    # -- goals and walkers ----------------------------------------------------------------
    def _goal_taken(self, driver: Driver, me: Body, others: list[Body]) -> bool:
        """Does another body stand still on this robot's goal?"""
        goal = driver.goal_point()
        low, high = HEIGHTS[me.kind]
        for other in others:
            if float(np.linalg.norm(other.velocity)) > 0.05 or other.kind == "lift":
                continue
            if other.z[1] < goal[2] + low or other.z[0] > goal[2] + high:
                continue
            if float(np.linalg.norm(other.xy - goal[:2])) < me.radius + other.radius + 0.1:
                return True
        return False

    def _climb(self, me: Body, others: list[Body], ahead: FloatArray) -> float:
        """How far a UAV climbs to pass over a walker on a collision course with it."""
        need = 0.0
        for other in others:
            if other.kind not in WALKERS or other.z[1] < me.base_z[0]:
                continue
            miss = _closest_approach(other.xy - me.xy, other.velocity - me.velocity,
                                     CLIMB_SOON)
            if miss < me.radius + other.radius + 0.3:
                need = max(need, other.z[1] + CLIMB_MARGIN - me.base_z[0])
        if need <= 0.0:
            return 0.0
        above = np.array([[*me.xy, me.base_z[1] + need], *[[*p[:2], p[2] + need]
                                                           for p in ahead[:3]]])
        return need if self.cosim.fits(me.name, above).all() else 0.0


def _closest_approach(rel: FloatArray, velocity: FloatArray, horizon: float) -> float:
    """The least distance over the next ``horizon`` s of a body at ``rel`` moving at
    ``velocity`` relative to a still observer."""
    speed2 = float(velocity @ velocity)
    t = 0.0 if speed2 < 1e-9 else min(max(-float(rel @ velocity) / speed2, 0.0), horizon)
    return float(np.linalg.norm(rel + velocity * t))
