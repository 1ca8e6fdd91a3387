"""The UAV's driver: the hexacopter flies a reference sampled from the kinematic motion.

The reference advances one control period a tick, but only while the craft keeps up with it
(within ``GOVERN``): a craft bumped or blocked waits for its reference instead of being pulled
after one that has gone on through a wall. Its progress is how far along the reference it
has got; the local layer may hold it (the reference stops), shift it aside, or lift it over a
walker.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from astralis_des.kernel.robot import Motion, Robot
from astralis_des.mission.spec import PhysicsSpec
from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.drivers import ARRIVED, DRIVERS, Avoiding, ramp, samples_along
from astralis_des.physics.hexacopter import Hexacopter
from astralis_des.world.geometry import FloatArray

GOVERN = 0.5  # m: farther than this from its reference point, the reference waits
CRASH_TILT = 60.0  # degrees: a multirotor tilted this far has lost its lift: crashed
COS_CRASH_TILT = math.cos(math.radians(CRASH_TILT))
FALL = 1.0  # m below its course (its controller holds it within centimetres): crashed
CLIMB_RATE = 1.2  # m/s: how fast it climbs over a walker, and comes back down


@DRIVERS.register("uav")
class UavDriver(Avoiding):
    """Flies a constant-speed reference along the path (the kinematic motion itself)."""

    def __init__(self, client: PhysicsClient, robot: Robot, spec: PhysicsSpec, urdf: Path) -> None:
        self.client = client
        self.spec = spec.uav
        self.period = 1.0 / spec.control_rate
        self.craft = Hexacopter(client, spec.uav, urdf, robot.pose, self.period)
        self.body = self.craft.body
        self.height = robot.height
        self.motion: Motion | None = None
        self.ref: FloatArray = np.asarray(robot.pose, dtype=float)[None, :]
        self.ref_s: FloatArray = np.zeros(1)
        self._last = 0
        self.k = 0
        self._clear_avoidance()
        self.freeze()

    def start(self, motion: Motion, t: float) -> None:
        """Wake the body and sample the whole reference at the control rate, once."""
        self.motion = motion
        self.client.call("changeDynamics", self.body, -1, mass=self.spec.mass,
                         localInertiaDiagonal=list(self.spec.inertia))
        self.client.call("resetBaseVelocity", self.body, [0, 0, 0], [0, 0, 0])
        ticks = np.arange(math.ceil(motion.duration / self.period) + 1)
        pos, vel = motion.sample(np.asarray(t + ticks * self.period, dtype=float))
        self.ref = pos
        self.ref_s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pos, axis=0),
                                                                     axis=1))])
        self.ref_pos, self.ref_vel = pos.tolist(), vel.tolist()
        self.ref_acc = _acceleration(vel, self.period, motion.accel).tolist()
        self.goal = pos[-1]
        self._last = len(pos) - 1
        self.k = 0  # the reference's clock, in ticks: it stops while the robot holds
        self.lag = 0.0
        self._clear_avoidance()

    @property
    def last(self) -> int:
        return len(self.ref) - 1

    def heading_vector(self) -> FloatArray:
        """Where it means to go (held or not): the reference's velocity, or at the end of
        the reference (or on a vertical leg) towards its point, if not yet there."""
        if self.motion is None:
            return np.zeros(2)
        k = min(self.k, self.last)
        vel = self.ref_vel[k]
        if math.hypot(vel[0], vel[1]) > 1e-3:
            return np.array(vel[:2])
        here = self.craft.position()
        gap = self.ref[k, :2] - here[:2]
        norm = float(np.hypot(*gap))
        return gap / norm * min(self.motion.speed, norm) if norm > ARRIVED else np.zeros(2)

    def progress(self) -> float:
        """Metres of the reference flown so far."""
        return float(self.ref_s[min(self.k, self.last)])

    def path_ahead(self, distance: float) -> FloatArray:
        """Points of the reference from where it is now to ``distance`` further."""
        return samples_along(self.ref, self.ref_s, self.progress(), distance)

    def goal_point(self) -> FloatArray:
        return np.asarray(self.ref[-1])

    def tick(self, t: float) -> str | None:
        last = self._last
        k = self.k if self.k < last else last
        if k >= last:
            pos, _, v, _ = self.craft.state()
            if math.dist(pos, self.goal) < self.arrive_within and math.hypot(*v) < 0.3:
                return "arrived"
        self.shift = ramp(self.shift, self.shift_to, self.shift_rate * self.period)
        self.lift_z = _toward(self.lift_z, self.lift_to, CLIMB_RATE * self.period)
        ref, (sx, sy) = self.ref_pos[k], self.shift.tolist()
        target = (ref[0] + sx, ref[1] + sy, ref[2] + self.lift_z)
        if self.held or self.lag > GOVERN:  # hold, or wait for the craft: fly to the point
            self.lag = self.craft.control(target, (0.0, 0.0, 0.0))
        else:
            self.k += 1
            self.lag = self.craft.control(target, self.ref_vel[k], a_ref=self.ref_acc[k])
        return None

    def course_z(self) -> float:
        """The height its reference flies at now (before any climb over a walker)."""
        return float(self.ref[min(self.k, self.last), 2])

    def position(self) -> FloatArray:
        return self.craft.position()

    def crashed(self) -> str | None:
        """Why the craft is down (tipped over, or fallen below its course), if it is."""
        (_, _, z), (qx, qy, _, _) = self.client.base_pose(self.body)  # checked at 30 Hz
        if 1.0 - 2.0 * (qx * qx + qy * qy) < COS_CRASH_TILT:
            return f"crashed: tipped over ({self.craft.tilt_deg():.0f} degrees)"
        drop = float(self.ref[min(self.k, self.last), 2]) - z
        if drop > FALL:
            return f"crashed: fell {drop:.1f} m below its course"
        return None

    def fall(self, floor: FloatArray) -> None:
        """Down on the floor below where it crashed, on its side, its rotors stopped (the
        fall itself is not simulated: the stepper stops with the motion)."""
        x, y, _ = self.craft.position()
        _, quat = self.client.call("getBasePositionAndOrientation", self.body)
        yaw = self.client.call("getEulerFromQuaternion", quat)[2]
        self.client.call("resetBasePositionAndOrientation", self.body,
                         [float(x), float(y), float(floor[2]) + self.spec.radius],
                         self.client.call("getQuaternionFromEuler", [math.pi / 2, 0.0, yaw]))
        self.craft.rotor_speed = [0.0] * len(self.craft.rotor_speed)

    def recover(self, at: FloatArray) -> None:
        """Set upright over ``at`` (the floor) at its flying height, still, rotors at hover."""
        self.client.call("resetBasePositionAndOrientation", self.body,
                         [float(at[0]), float(at[1]), float(at[2]) + self.height],
                         [0.0, 0.0, 0.0, 1.0])
        self.craft.rotor_speed = [self.craft.hover_speed] * len(self.craft.rotor_speed)
        self.freeze()

    def freeze(self) -> None:
        """Hold still as a static body: a waiting UAV costs the solver nothing."""
        self.client.call("changeDynamics", self.body, -1, mass=0.0)
        self.client.call("resetBaseVelocity", self.body, [0, 0, 0], [0, 0, 0])


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


def _toward(current: float, target: float, step: float) -> float:
    if abs(target - current) <= step:
        return target
    return current + math.copysign(step, target - current)
