"""The UGV's driver: pure pursuit on each floor, the stairwell's lift between floors, and a
back-off when its way forward is blocked.

A path is split into legs: floor legs the Husky drives, and rides (a leg that climbs more
than ``LIFT_RISE``) on the lift (:mod:`.lift`). Before a ride the UGV reserves the lift and
waits at the edge of its column until the platform is at its floor; it frees the lift once its
body is out of the column again. Its progress counts the path driven, the height ridden and
the turning done on the spot, so a wedged UGV makes none.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from astralis_des.kernel.robot import Motion, Robot
from astralis_des.mission.spec import PhysicsSpec
from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.drivers import DRIVERS, Avoiding, ramp, samples_along
from astralis_des.physics.husky import REST_Z, Husky
from astralis_des.physics.lift import Lift
from astralis_des.world.geometry import FloatArray

UGV_RATE = 40  # Hz: pure pursuit updates (when the control rate is a multiple of it)
FACING = 0.08  # rad: close enough to the heading asked for
STOPPED = 0.05  # m/s: slower than this it has stopped (and may turn on the spot)
LIFT_RISE = 0.3  # m: a leg climbing more than this is ridden on the stairwell's lift
CALL_RANGE = 2.5  # m from the lift's column: reserve it, and call it to this floor
WAIT_AT = 0.8  # m from the column: wait here while the platform is not at this floor
TURN_METRES = 0.3  # progress credited per radian turned on the spot
BACK_OFF_AFTER = 2.5  # s without progress while driving: back off
BACK_OFF_TIME = 1.2  # s of reversing
BACK_OFF_SPEED = 0.35  # m/s
BACK_OFFS = 2  # at most this many per leg; then the stuck test decides
CRASH_TILT = 45.0  # degrees of roll or pitch: the Husky is on its side
FALL = 0.5  # m below the floor it drives on: it fell off it
SUPPORT = 0.7  # a contact normal steeper than this is the floor holding it up

Leg = tuple[bool, FloatArray]  # (a ride on the lift, floor-level points)


@DRIVERS.register("ugv")
class UgvDriver(Avoiding):
    def __init__(self, client: PhysicsClient, robot: Robot, spec: PhysicsSpec, urdf: Path) -> None:
        self.client = client
        self.id = robot.id
        self.height = robot.height
        self.floor = float(robot.pose[2] - robot.height)
        self.husky = Husky(client, robot.pose - np.array([0.0, 0.0, robot.height]),
                           sleeps=spec.sleep_idle)
        self.body = self.husky.body
        self.husky.rest()
        self.legs: list[Leg] = []
        self.speed = robot.speed
        self.ride: tuple[Lift, float, float] | None = None  # the lift, from and to levels
        self.lifts: list[Lift] = []  # set by the co-simulation
        self.column_busy: Callable[[Lift, str], bool] = lambda lift, rider: False
        self.period = 1.0 / spec.control_rate
        self.every = max(1, round(spec.control_rate / UGV_RATE))
        self._ticks = 0
        self.turning = False
        self.heading = 0.0
        self.motion: Motion | None = None
        self.done_s = 0.0  # metres of the path's legs already finished
        self.turned = 0.0  # radians turned on the spot during this motion
        self._yaw = 0.0
        self._best = (0.0, 0.0)  # (progress, time it was reached): for the back-off
        self.backing_until = -1.0
        self.back_offs = 0
        self._clear_avoidance()

    # -- what the others see ---------------------------------------------------------------
    def heading_vector(self) -> FloatArray:
        """The way it is headed along its path (it may first turn to face it)."""
        if self.turning or self.ride is not None or not len(self.husky.path):
            return np.zeros(2)
        x, y, _, _ = self.husky.pose()
        gx, gy = self.husky.aim()
        norm = math.hypot(gx - x, gy - y)
        return np.array([gx - x, gy - y]) / norm * self.speed if norm > 0.05 else np.zeros(2)

    def progress(self) -> float:
        ride = 0.0
        if self.ride is not None:
            ride = abs(self.ride[0].z - self.ride[1])
        on_leg = self.husky.progress if self.ride is None else ride
        return self.done_s + on_leg + TURN_METRES * self.turned

    def path_ahead(self, distance: float) -> FloatArray:
        if self.motion is None:
            return self.position()[None, :]
        start = min(self.done_s + (self.husky.progress if self.ride is None else 0.0),
                    float(self.motion.cum[-1]))
        return samples_along(self.motion.points, self.motion.cum, start, distance)

    def goal_point(self) -> FloatArray:
        return self.position() if self.motion is None else np.asarray(self.motion.points[-1])

    def position(self) -> FloatArray:
        """Where its sensor is: the body's own height (on whatever floor carries it)."""
        x, y, z, _ = self.husky.pose()
        return np.array([x, y, z - REST_Z + self.height])

    # -- motions ---------------------------------------------------------------------------
    def turn_to(self, heading: float) -> bool:
        """Turn on the spot until the body faces ``heading`` (True: it turns)."""
        self.husky.wake()
        self.legs = []
        self.ride = None
        self.motion = None
        self.turning = True
        self.heading = heading
        self.turned = 0.0
        self._yaw = self.husky.pose()[3]
        self._clear_avoidance()
        return True

    def start(self, motion: Motion, t: float) -> None:
        self.husky.wake()
        self.turning = False
        self.motion = motion
        floor = motion.points - np.array([0.0, 0.0, self.height])
        legs: list[Leg] = []
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
        self.done_s = 0.0
        self.turned = 0.0
        self._yaw = self.husky.pose()[3]
        self.back_offs = 0
        self.backing_until = -1.0
        self._clear_avoidance()
        self._leg_length = 0.0
        self._next_leg(t)

    def _next_leg(self, t: float) -> None:
        self.done_s += self._leg_length
        self.ride = None
        self._best = (self.progress(), t)
        self.back_offs = 0
        if not self.legs:
            return
        ride, points = self.legs.pop(0)
        self._leg_length = float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
        if ride:
            lift = self._lift_at(points[0])
            if lift is None:  # a climb with no lift under it: driven like any leg
                self.husky.follow(points, self.speed)
                return
            self.ride = (lift, float(points[0][2]), float(points[1][2]))
        else:
            self.floor = float(points[-1][2])
            self.husky.follow(points, self.speed)

    def _lift_at(self, point: FloatArray) -> Lift | None:
        return next((lift for lift in self.lifts if lift.contains(point)), None)

    # -- the control period ----------------------------------------------------------------
    def _count_turning(self) -> None:
        """Add the turn on the spot since the last look to the progress made."""
        yaw = self.husky.pose()[3]
        if self.turning or self.husky.spinning:
            self.turned += abs(math.remainder(yaw - self._yaw, math.tau))
        self._yaw = yaw

    def tick(self, t: float) -> str | None:
        if self.turning:
            self._count_turning()
            return self._turn()
        self._free_lift()
        if self.ride is not None:
            return self._ride(t)
        if self.held or self._wait_for_lift():
            self.husky.drive(0.0, 0.0)
            self._best = (self.progress(), t)  # waiting is not being blocked
            if self.held:  # its way round what holds it is set while it waits (else the
                # hold, for a body on the unshifted way, never ends)
                self.shift = ramp(self.shift, self.shift_to, self.shift_rate * self.period)
                self.husky.offset = self.shift
            return None
        if t < self.backing_until:
            self.husky.drive(-BACK_OFF_SPEED, 0.0)
            return None
        self._ticks += 1
        if self._ticks % self.every:  # the wheel motors hold their targets
            return None
        self._count_turning()
        self._check_blocked(t)
        self.shift = ramp(self.shift, self.shift_to, self.shift_rate * self.period * self.every)
        self.husky.offset = self.shift
        if self.husky.track(self.arrive_within):
            if not self.legs:
                return "arrived"
            self._next_leg(t)
        return None

    def _turn(self) -> str | None:
        """Brake to a stop, then turn on the spot (turning while it still rolls would carry
        it on, skidding, half a metre past where it was asked to look from)."""
        if abs(self.husky.velocity_in_body()[0]) > STOPPED:
            self.husky.drive(0.0, 0.0)
            return None
        error = math.remainder(self.heading - self.husky.pose()[3], math.tau)
        if abs(error) < FACING:
            self.husky.drive(0.0, 0.0)
            self.turning = False
            return "arrived"
        self.husky.drive(0.0, math.copysign(min(1.0, 2.0 * abs(error) + 0.3), error))
        return None

    def _check_blocked(self, t: float) -> None:
        """No progress for a while, not held, and pressing on something (a wall, furniture,
        a body): reverse a little and try again."""
        progress = self.progress()
        if progress > self._best[0] + 0.05:
            self._best = (progress, t)
        elif t - self._best[1] > BACK_OFF_AFTER and self.back_offs < BACK_OFFS and \
                self._pressing():
            self.back_offs += 1
            self.backing_until = t + BACK_OFF_TIME
            self._best = (progress, t + BACK_OFF_TIME)

    def _pressing(self) -> bool:
        """Is the body touching something other than the floor it stands on?"""
        return any(c[7][2] < SUPPORT for c in self.client.call("getContactPoints",
                                                                bodyA=self.body))

    def _ride(self, t: float) -> str | None:
        lift, z_from, z_to = self.ride  # type: ignore[misc]
        self.husky.drive(0.0, 0.0)
        if not lift.reserve(self.id):
            return None
        if abs(lift.z - z_from) > 1e-6 and abs(lift.z - z_to) > 1e-6 and not (
                min(z_from, z_to) < lift.z < max(z_from, z_to)):
            return None  # the platform is elsewhere: it was called, it is not here yet
        if self.column_busy(lift, self.id):
            lift.moving = False  # someone else is in the column: the lift waits for it
            return None
        there = lift.move_towards(z_to, self.speed * self.period)
        x, y, _, yaw = self.husky.pose()
        self.client.call("resetBasePositionAndOrientation", self.body,
                         [x, y, lift.z + REST_Z],
                         self.client.call("getQuaternionFromEuler", [0, 0, yaw]))
        self.client.call("resetBaseVelocity", self.body, [0, 0, 0], [0, 0, 0])
        self.floor = lift.z
        if there:
            self._next_leg(t)
            if not self.legs and self.ride is None and not len(self.husky.path):
                return "arrived"
        return None

    def _wait_for_lift(self) -> bool:
        """On a floor leg that ends at a ride: reserve the lift near its column, call the
        platform to this floor, and wait at the column's edge until it is here."""
        if not self.legs or not self.legs[0][0]:
            return False
        lift = self._lift_at(self.legs[0][1][0])
        if lift is None:
            return False
        here = self.husky.position()
        if not lift.contains(here, CALL_RANGE):
            return False
        if not lift.reserve(self.id):
            return not lift.contains(here, WAIT_AT) and lift.contains(here, WAIT_AT + 0.5)
        if abs(lift.z - self.floor) > 1e-6:
            if self.column_busy(lift, self.id):
                lift.moving = False
            else:
                lift.move_towards(self.floor, self.speed * self.period)
            return lift.contains(here, WAIT_AT)
        lift.moving = False
        return False

    def _free_lift(self) -> None:
        """Out of the column after a ride (or never going in): the lift is free again."""
        for lift in self.lifts:
            if lift.rider == self.id and self.ride is None and not lift.contains(
                    self.husky.position(), 0.7) and not self._wants(lift):
                lift.release(self.id)

    def _wants(self, lift: Lift) -> bool:
        return bool(self.legs) and self.legs[0][0] and lift.contains(self.legs[0][1][0])

    def slow_down(self, share: float) -> None:
        self.husky.limit = share * self.speed if share < 1.0 else math.inf

    def crashed(self) -> str | None:
        """Why the Husky is down (on its side, or fallen off its floor), if it is."""
        if self.ride is not None:
            return None
        tilt = self.husky.tilt_deg()
        if tilt > CRASH_TILT:
            return f"crashed: tipped over ({tilt:.0f} degrees)"
        drop = self.floor - (self.husky.pose()[2] - REST_Z)
        if drop > FALL:
            return f"crashed: fell {drop:.1f} m"
        return None

    def fall(self, floor: FloatArray) -> None:
        """A Husky on its side stays as it lies (it is simulated to rest already)."""

    def recover(self, at: FloatArray) -> None:
        """Set upright on its wheels at ``at`` (floor level)."""
        yaw = self.husky.pose()[3]
        self.client.call("resetBasePositionAndOrientation", self.body,
                         [float(at[0]), float(at[1]), float(at[2]) + REST_Z],
                         self.client.call("getQuaternionFromEuler", [0, 0, yaw]))
        self.client.call("resetBaseVelocity", self.body, [0, 0, 0], [0, 0, 0])
        self.floor = float(at[2])
        self.wake()  # to settle where it was put

    def wake(self) -> None:
        """Awake (a mover comes near, it was put somewhere); asleep again once settled. A
        driven body is awake already."""
        if self.husky.resting:
            self.husky.wake()
            self.husky.rest()

    def freeze(self) -> None:
        """Stop the wheels. Halted in the middle of a ride, the lift first brings it to the
        nearer floor (a lift does not stop between floors)."""
        self.husky.drive(0.0, 0.0)
        if self.ride is not None:
            lift, z_from, z_to = self.ride
            level = z_from if abs(lift.z - z_from) <= abs(lift.z - z_to) else z_to
            lift.move_towards(level, abs(level - lift.z))
            x, y, _, yaw = self.husky.pose()
            self.client.call("resetBasePositionAndOrientation", self.body,
                             [x, y, level + REST_Z],
                             self.client.call("getQuaternionFromEuler", [0, 0, yaw]))
            self.floor = level
            lift.moving = False
            self.ride = None
        self.husky.rest()
