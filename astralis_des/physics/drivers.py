"""Drivers: each robot kind's body and controller behind one interface for the stepper.

``start(motion, t)`` begins a motion; ``tick(t)`` applies the commands for the next control
period and returns ``None`` while the motion goes on, else ``"arrived"``; ``position()`` is
the robot's pose (its sensor's position, as in the kinematic fidelity).
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Protocol

import numpy as np

from astralis_des.kernel.robot import Motion, Robot
from astralis_des.mission.spec import PhysicsSpec
from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.hexacopter import Hexacopter
from astralis_des.physics.husky import Husky
from astralis_des.physics.walker import HEIGHT, RADIUS, Walker
from astralis_des.registry import Registry
from astralis_des.world.geometry import FloatArray

ARRIVED = 0.2  # m from the end of its path, nearly still: a UAV has arrived
SHIFT_RATE = 1.2  # m/s: how fast a robot moves aside to keep right, or back
UGV_RATE = 40  # Hz: pure pursuit updates (when the control rate is a multiple of it)
FACING = 0.08  # rad: close enough to the heading asked for
LIFT_RISE = 0.3  # m: a leg climbing more than this is ridden on the stairwell's vehicle lift


class Driver(Protocol):
    body: int

    def start(self, motion: Motion, t: float) -> None: ...
    def tick(self, t: float) -> str | None: ...
    def position(self) -> FloatArray: ...
    def freeze(self) -> None: ...
    def heading_vector(self) -> FloatArray: ...
    def avoid(self, hold: bool, shift: FloatArray) -> None: ...
    def slow_down(self, share: float) -> None: ...


DRIVERS: Registry[str, type] = Registry("driver")


class Avoiding:
    """What the local layer sets on a driver: hold still, and how far to stand aside."""

    held: bool = False
    shift: FloatArray
    shift_to: FloatArray

    def _clear_avoidance(self) -> None:
        self.held = False
        self.shift = np.zeros(2)
        self.shift_to = np.zeros(2)

    def avoid(self, hold: bool, shift: FloatArray) -> None:
        self.held, self.shift_to = hold, np.asarray(shift, dtype=float)

    def slow_down(self, share: float) -> None:
        """Obstacles ahead (the lidar): go at most ``share`` of the speed. Only a UGV does."""


@DRIVERS.register("uav")
class UavDriver(Avoiding):
    """Flies a constant-speed reference along the path (the kinematic motion itself)."""

    def __init__(self, client: PhysicsClient, robot: Robot, spec: PhysicsSpec, urdf: Path) -> None:
        self.client = client
        self.spec = spec.uav
        self.period = 1.0 / spec.control_rate
        self.craft = Hexacopter(client, spec.uav, urdf, robot.pose, self.period)
        self.body = self.craft.body
        self.motion: Motion | None = None
        self.freeze()

    def start(self, motion: Motion, t: float) -> None:
        """Wake the body and sample the whole reference at the control rate, once."""
        self.motion = motion
        self.client.call("changeDynamics", self.body, -1, mass=self.spec.mass,
                         localInertiaDiagonal=list(self.spec.inertia))
        self.client.call("resetBaseVelocity", self.body, [0, 0, 0], [0, 0, 0])
        ticks = np.arange(math.ceil(motion.duration / self.period) + 1)
        self.t0 = t
        self.end = t + motion.duration
        pos, vel = motion.sample(np.asarray(t + ticks * self.period, dtype=float))
        self.ref_pos, self.ref_vel = pos.tolist(), vel.tolist()
        self.ref_acc = _acceleration(vel, self.period, motion.accel).tolist()
        self.goal = pos[-1]
        self.k = 0  # the reference's clock, in ticks: it stops while the robot holds
        self._clear_avoidance()

    def heading_vector(self) -> FloatArray:
        if self.motion is None or self.held:
            return np.zeros(2)
        vel = self.ref_vel[min(self.k, len(self.ref_vel) - 1)]
        return np.array(vel[:2])

    def tick(self, t: float) -> str | None:
        last = len(self.ref_pos) - 1
        k = min(self.k, last)
        if k >= last:
            pos, _, v, _ = self.craft.state()
            if math.dist(pos, self.goal) < ARRIVED and math.hypot(*v) < 0.3:
                return "arrived"
        if not self.held:
            self.k += 1
        self.shift = _ramp(self.shift, self.shift_to, SHIFT_RATE * self.period)
        ref = self.ref_pos[k]
        target = (ref[0] + self.shift[0], ref[1] + self.shift[1], ref[2])
        if self.held:
            self.craft.control(target, (0.0, 0.0, 0.0))
        else:
            self.craft.control(target, self.ref_vel[k], a_ref=self.ref_acc[k])
        return None

    def position(self) -> FloatArray:
        return self.craft.position()

    def freeze(self) -> None:
        """Hold still as a static body: a waiting UAV costs the solver nothing."""
        self.client.call("changeDynamics", self.body, -1, mass=0.0)
        self.client.call("resetBaseVelocity", self.body, [0, 0, 0], [0, 0, 0])


@DRIVERS.register("ugv")
class UgvDriver(Avoiding):
    """Pure pursuit on each floor; between floors the stairwell's lift carries it."""

    def __init__(self, client: PhysicsClient, robot: Robot, spec: PhysicsSpec, urdf: Path) -> None:
        self.client = client
        self.height = robot.height
        self.floor = float(robot.pose[2] - robot.height)
        self.husky = Husky(client, robot.pose - np.array([0.0, 0.0, robot.height]))
        self.body = self.husky.body
        self.legs: list[tuple[bool, FloatArray]] = []
        self.speed = robot.speed
        self.lift: tuple[float, FloatArray] | None = None
        self.period = 1.0 / spec.control_rate
        self.every = max(1, round(spec.control_rate / UGV_RATE))
        self._ticks = 0
        self.turning = False
        self.heading = 0.0
        self._clear_avoidance()

    def heading_vector(self) -> FloatArray:
        if self.held or self.turning or self.lift is not None or not len(self.husky.path):
            return np.zeros(2)
        yaw = self.husky.pose()[3]
        return np.array([math.cos(yaw), math.sin(yaw)]) * self.speed

    def turn_to(self, heading: float) -> None:
        """Turn on the spot until the body faces ``heading``."""
        self.legs = []
        self.lift = None
        self.turning = True
        self.heading = heading

    def start(self, motion: Motion, t: float) -> None:
        self.turning = False
        floor = motion.points - np.array([0.0, 0.0, self.height])
        legs: list[tuple[bool, FloatArray]] = []
        run = [floor[0]]
        for a, b in itertools.pairwise(floor):
            if abs(b[2] - a[2]) > LIFT_RISE:
                if len(run) > 1:
                    legs.append((False, np.array(run)))
                legs.append((True, np.array([a, b])))
                run = [b]
            else:
                run.append(b)
        if len(run) > 1:
            legs.append((False, np.array(run)))
        self.legs = legs
        self.speed = motion.speed
        self._next_leg(t)

    def _next_leg(self, t: float) -> None:
        self.lift = None
        if not self.legs:
            return
        ride, points = self.legs.pop(0)
        if ride:
            self.lift = (t, points)
        else:
            self.floor = float(points[-1][2])
            self.husky.follow(points, self.speed)

    def tick(self, t: float) -> str | None:
        if self.turning:
            error = math.remainder(self.heading - self.husky.pose()[3], math.tau)
            if abs(error) < FACING:
                self.husky.drive(0.0, 0.0)
                self.turning = False
                return "arrived"
            self.husky.drive(0.0, math.copysign(min(1.0, 2.0 * abs(error) + 0.3), error))
            return None
        if self.lift is not None:
            t0, (a, b) = self.lift
            share = min((t - t0) * self.speed / max(float(np.linalg.norm(b - a)), 1e-9), 1.0)
            x, y, _z, yaw = self.husky.pose()
            here = a + (b - a) * share
            self.client.call("resetBasePositionAndOrientation", self.body,
                             [x, y, float(here[2]) + 0.15],
                             self.client.call("getQuaternionFromEuler", [0, 0, yaw]))
            self.client.call("resetBaseVelocity", self.body, [0, 0, 0], [0, 0, 0])
            self.floor = float(here[2])
            if share >= 1.0:
                self._next_leg(t)
            return None
        if self.held:
            self.husky.drive(0.0, 0.0)
            return None
        self._ticks += 1
        if self._ticks % self.every and not self.lift:  # the wheel motors hold their targets
            return None
        self.shift = _ramp(self.shift, self.shift_to, SHIFT_RATE * self.period * self.every)
        self.husky.offset = self.shift
        if self.husky.track():
            if not self.legs:
                return "arrived"
            self._next_leg(t)
        return None

    def slow_down(self, share: float) -> None:
        self.husky.limit = share * self.speed if share < 1.0 else math.inf

    def position(self) -> FloatArray:
        x, y, _, _ = self.husky.pose()
        return np.array([x, y, self.floor + self.height])

    def freeze(self) -> None:
        self.husky.drive(0.0, 0.0)


@DRIVERS.register("human")
class HumanDriver(Avoiding):
    """Walks the path at its speed, kinematically: a capsule placed at each tick."""

    def __init__(self, client: PhysicsClient, robot: Robot, spec: PhysicsSpec, urdf: Path) -> None:
        self.offset = np.array([0.0, 0.0, robot.height - (RADIUS + HEIGHT / 2)])
        self.period = 1.0 / spec.control_rate
        self.walker = Walker(client, robot.pose - self.offset)
        self.body = self.walker.body
        self.motion: Motion | None = None

    def start(self, motion: Motion, t: float) -> None:
        self.motion = motion
        self.elapsed = 0.0  # walking time so far: it stops while the walker waits
        self._clear_avoidance()

    def heading_vector(self) -> FloatArray:
        if self.motion is None or self.held:
            return np.zeros(2)
        return np.asarray(self.motion.velocity(self.motion.t0 + self.elapsed)[:2])

    def tick(self, t: float) -> str | None:
        assert self.motion is not None
        if not self.held:
            self.elapsed += self.period
        self.shift = _ramp(self.shift, self.shift_to, SHIFT_RATE * self.period)
        where = self.motion.at(self.motion.t0 + self.elapsed) - self.offset
        where[:2] += self.shift
        self.walker.place(where)
        return "arrived" if self.elapsed >= self.motion.duration else None

    def position(self) -> FloatArray:
        return self.walker.position() + self.offset

    def freeze(self) -> None:
        """A walker is kinematic: standing still costs nothing."""


def _acceleration(velocity: FloatArray, period: float, limit: float | None) -> FloatArray:
    """The reference's acceleration at each tick (central differences), capped at the
    profile's: a corner's sudden turn of the velocity would otherwise ask for a kick."""
    if len(velocity) < 2 or not limit:
        return np.zeros_like(velocity)
    acc = np.gradient(velocity, period, axis=0)
    acc[-1] = 0.0  # the reference rests at its end: holding there needs no push
    norm = np.linalg.norm(acc, axis=1, keepdims=True)
    out: FloatArray = acc * np.minimum(1.0, limit / np.maximum(norm, 1e-12))
    return out


def _ramp(current: FloatArray, target: FloatArray, step: float) -> FloatArray:
    """Move ``current`` towards ``target`` by at most ``step`` (plain floats: every tick)."""
    dx, dy = float(target[0] - current[0]), float(target[1] - current[1])
    if dx == 0.0 and dy == 0.0:
        return current
    norm = math.hypot(dx, dy)
    if norm <= step:
        return np.array([float(target[0]), float(target[1])])
    k = step / norm
    return np.array([float(current[0]) + dx * k, float(current[1]) + dy * k])
