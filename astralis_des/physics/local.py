"""The local layer: robots in physics avoid what moves (other robots, patrolling avatars,
moving obstacles), from what each knows of the others' positions, at the contact-check rate.

Two rules, as people keep to in corridors:
- keep right: something coming head-on within ``PASS_RANGE`` makes the robot shift to its right
  (as far as the map leaves room), so that both pass side by side;
- hold: something in the robot's lane, closer than its stopping range, makes it wait (its
  reference stops: a UAV hovers, the UGV stops, a walker stands). Between two robots only the
  lower-priority one holds (team order), so they never wait for each other; scripted movers
  and robots standing still never yield, so robots always do;
- step aside: something standing still in the lane is passed on the side with room.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.world.geometry import FloatArray

if TYPE_CHECKING:
    from astralis_des.cosim.physics import PhysicsCoSim

PASS_RANGE = 5.0  # m: closer than this, head-on, both keep right
LOOK_AHEAD = 0.8  # s: where the others will be, for the lane test
BRAKING = 1.0  # s: the stopping range grows by this times the robot's speed
SHIFT = 0.7  # m to the right at most
STOP_RANGE = 0.8  # m between bodies' edges ahead: hold
LANE_MARGIN = 0.15  # m added to the two radii to decide "in my lane"
HEIGHTS = {"uav": (-0.1, 0.1), "ugv": (-0.5, 0.0), "human": (-1.6, 0.15)}  # around the pose
RADII = {"uav": 0.3, "ugv": 0.4, "human": 0.25}
STILL_RANK = 10_000  # movers, and robots not moving: everyone yields to them
NEAR = 6.0  # m: movers farther than this from every moving robot need not move in physics
RATE = 5.0  # Hz: how often the layer decides (a UAV flies 0.3 m in between)


@dataclass
class Body:
    name: str
    xy: FloatArray
    velocity: FloatArray  # xy
    z: tuple[float, float]
    radius: float
    rank: int  # lower yields to higher; movers rank above every robot


class LocalLayer:
    def __init__(self, cosim: PhysicsCoSim, order: list[str]) -> None:
        self.cosim = cosim
        self.rank = {rid: len(order) - i for i, rid in enumerate(order)}
        self.holds = 0  # how many times a robot was held (for tests and benchmarks)
        self.near: list[int] = []  # movers within NEAR of a moving robot: the ones to move

    def bodies(self, t: float) -> list[Body]:
        found = []
        for rid, driver in self.cosim.drivers.items():
            robot = self.cosim.robots[rid]
            here = driver.position()
            low, high = HEIGHTS[robot.kind]
            velocity = driver.heading_vector()
            # a robot that is not moving cannot yield: it ranks with the movers
            rank = self.rank[rid] if rid in self.cosim.active else STILL_RANK
            found.append(Body(rid, here[:2], velocity, (here[2] + low, here[2] + high),
                              RADII[robot.kind], rank))
        for mover, _ in self.cosim.movers:
            here = mover.position_at(t)
            ahead = mover.position_at(t + 0.5)
            half = mover.size[2] / 2
            found.append(Body(mover.id, here[:2], (ahead[:2] - here[:2]) / 0.5,
                              (here[2] - half, here[2] + half),
                              max(mover.size[0], mover.size[1]) / 2, STILL_RANK))
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
        gaps = np.linalg.norm(where[robots:, None, :] - moving[None, :, :], axis=2)
        self.near = [int(i) for i in np.flatnonzero((gaps < NEAR).any(axis=1))]
        for rid in self.cosim.active:
            driver = self.cosim.drivers[rid]
            me = next(b for b in bodies if b.name == rid)
            direction = driver.heading_vector()
            speed = float(np.linalg.norm(direction))
            if speed < 1e-6:
                driver.avoid(False, np.zeros(2))
                continue
            forward = direction / speed
            right = np.array([forward[1], -forward[0]])
            near = np.linalg.norm(where - me.xy, axis=1) < PASS_RANGE + 1.0
            hold, shift = self._decide(me, [b for b, c in zip(bodies, near, strict=True) if c],
                                       forward, right, speed)
            if shift and not self._room_to_the_side(me, right, shift):
                shift = 0.0
            self.holds += hold
            driver.avoid(hold, right * shift)

    def _decide(self, me: Body, others: list[Body], forward: FloatArray,
                right: FloatArray, speed: float = 1.0) -> tuple[bool, float]:
        hold, shift = False, 0.0
        for other in others:
            if other.name == me.name or other.z[1] < me.z[0] or other.z[0] > me.z[1]:
                continue  # itself, or above or below it (a UAV over the UGV)
            rel = other.xy - me.xy
            along, across = float(rel @ forward), float(rel @ right)
            gap = math.hypot(along, across) - me.radius - other.radius
            lane = me.radius + other.radius + LANE_MARGIN
            if along <= 0 or gap > PASS_RANGE:
                continue
            if float(other.velocity @ forward) < -0.05:
                shift = max(shift, SHIFT)  # it comes towards us: keep right
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

    def _room_to_the_side(self, me: Body, right: FloatArray, shift: float) -> bool:
        """Is there room to shift ``shift`` to the right (left if negative), on the map?"""
        where = np.array([[*(me.xy + right * shift), (me.z[0] + me.z[1]) / 2]])
        return bool(self.cosim.clearance(where)[0] > me.radius + 0.05)
