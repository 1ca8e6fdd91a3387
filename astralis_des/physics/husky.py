"""The Husky UGV from ``pybullet_data``, driven only through its four wheel joints.

Loaded with implicit cylinders for its wheels (the URDF's own cylinders, not tessellated) and
its fixed links merged: the same robot, at half the contact cost. A pure-pursuit follower
turns the path into a speed and a curvature, and those into wheel speeds (skid steering).
"""

from __future__ import annotations

import bisect
import math

import numpy as np
import pybullet as pb

from astralis_des.physics.client import PhysicsClient, quiet_c_output
from astralis_des.world.geometry import FloatArray

WHEEL_RADIUS = 0.17775
TRACK = 0.5709  # m between left and right wheels
SKID = 3.5  # skid-steered: the effective track is wider than the geometric one (measured)
WHEEL_TORQUE = 120.0  # N m per wheel
LOOKAHEAD = 0.8  # m
ARRIVED = 0.2  # m from the end of the path
NEAR = 0.3  # m: a goal this close beside the robot counts as reached
MAX_TURN_RATE = 1.2  # rad/s
DECEL = 1.0  # m/s^2
REST_Z = 0.155  # m: the base's height above the floor it stands on (measured at rest)


class Husky:
    def __init__(self, client: PhysicsClient, start: FloatArray, sleeps: bool = False) -> None:
        """``sleeps``: standing idle (``rest``), it may sleep in Bullet."""
        self.client = client
        self.sleeps = sleeps
        self.resting = False  # idle, and allowed to sleep
        with quiet_c_output():
            self.body = int(client.call(
                "loadURDF", "husky/husky.urdf", [float(start[0]), float(start[1]),
                                                 float(start[2]) + REST_Z],
                flags=pb.URDF_USE_IMPLICIT_CYLINDER | pb.URDF_MERGE_FIXED_LINKS))
        names = {client.call("getJointInfo", self.body, j)[1].decode(): j
                 for j in range(client.call("getNumJoints", self.body))}
        self.left = [names["front_left_wheel"], names["rear_left_wheel"]]
        self.right = [names["front_right_wheel"], names["rear_right_wheel"]]
        self.wheels = self.left + self.right
        self.path: FloatArray = np.zeros((0, 2))
        self.cum: FloatArray = np.zeros(1)
        self._points: list[list[float]] = []
        self._lengths: list[float] = [0.0]
        self.progress = 0.0
        self.speed = 1.0
        self.limit = math.inf  # m/s: a cap the local planner sets (obstacles ahead)
        self.offset = np.zeros(2)  # shift of the pursued point (keeping right)
        self.spinning = False  # turning on the spot to face the path
        self.drive(0.0, 0.0)

    def rest(self) -> None:
        """Standing idle: Bullet may put it to sleep once it has settled (it then costs the
        solver next to nothing) and wakes it when a moving body touches it."""
        self.resting = True
        if self.sleeps:
            self.client.call("changeDynamics", self.body, -1,
                             activationState=pb.ACTIVATION_STATE_ENABLE_SLEEPING)

    def wake(self) -> None:
        """Awake and kept awake: it is driven (a sleeping body would not answer its wheels)."""
        self.resting = False
        if self.sleeps:
            self.client.call("changeDynamics", self.body, -1,
                             activationState=pb.ACTIVATION_STATE_WAKE_UP
                             | pb.ACTIVATION_STATE_DISABLE_SLEEPING)

    def pose(self) -> tuple[float, float, float, float]:
        """x, y, z of the base, and heading."""
        (x, y, z), quat = self.client.base_pose(self.body)
        yaw = pb.getEulerFromQuaternion(quat)[2]
        return x, y, z, yaw

    def position(self) -> FloatArray:
        x, y, z, _ = self.pose()
        return np.array([x, y, z])

    def tilt_deg(self) -> float:
        """Degrees between the body's z axis and the vertical (roll and pitch together)."""
        _, (qx, qy, _, _) = self.client.base_pose(self.body)
        return math.degrees(math.acos(min(max(1.0 - 2.0 * (qx * qx + qy * qy), -1.0), 1.0)))

    def velocity_in_body(self) -> tuple[float, float]:
        """Forward and lateral speed, m/s: a non-holonomic robot keeps the second near 0."""
        (vx, vy, _), _ = self.client.base_velocity(self.body)
        yaw = self.pose()[3]
        return vx * math.cos(yaw) + vy * math.sin(yaw), -vx * math.sin(yaw) + vy * math.cos(yaw)

    def drive(self, speed: float, turn_rate: float) -> None:
        """Wheel speeds for a forward speed (m/s) and a turn rate (rad/s)."""
        half = turn_rate * TRACK * SKID / 2
        left, right = (speed - half) / WHEEL_RADIUS, (speed + half) / WHEEL_RADIUS
        pb.setJointMotorControlArray(self.body, self.wheels, pb.VELOCITY_CONTROL,
                                     targetVelocities=[left, left, right, right],
                                     forces=[WHEEL_TORQUE] * 4, physicsClientId=self.client.id)

    def follow(self, path: FloatArray, speed: float) -> None:
        self.path = np.asarray(path, dtype=float)[:, :2]
        seg = np.linalg.norm(np.diff(self.path, axis=0), axis=1)
        self.cum = np.concatenate([[0.0], np.cumsum(seg)])
        self._points, self._lengths = self.path.tolist(), self.cum.tolist()  # plain floats
        self.progress = 0.0  # arc length of the robot's projection on the path, never back
        self.speed = speed

    def _project(self, x: float, y: float) -> float:
        """Arc length of the closest point of the path ahead of the current progress."""
        best_s, best_d = self.progress, math.inf
        points, cum = self._points, self._lengths
        first = max(bisect.bisect_right(cum, self.progress) - 1, 0)
        for i in range(first, len(points) - 1):
            a, b = points[i], points[i + 1]
            length = cum[i + 1] - cum[i]
            if length < 1e-9:
                continue
            u = min(max(((x - a[0]) * (b[0] - a[0]) + (y - a[1]) * (b[1] - a[1]))
                        / (length * length), 0.0), 1.0)
            d = math.hypot(a[0] + u * (b[0] - a[0]) - x, a[1] + u * (b[1] - a[1]) - y)
            if d < best_d - 1e-9:
                best_s, best_d = cum[i] + u * length, d
            if cum[i] > self.progress + 2 * LOOKAHEAD:
                break
        return max(best_s, self.progress)

    def aim(self) -> tuple[float, float]:
        """Where it is headed: the pursued point of its path (not the way it faces)."""
        return self._point_at(self.progress + LOOKAHEAD)

    def _point_at(self, s: float) -> tuple[float, float]:
        s = min(s, float(self.cum[-1]))
        return (float(np.interp(s, self.cum, self.path[:, 0])),
                float(np.interp(s, self.cum, self.path[:, 1])))

    def track(self, arrive_within: float = ARRIVED) -> bool:
        """One pure-pursuit update; true once the end of the path is reached (within
        ``arrive_within``)."""
        x, y, _, yaw = self.pose()
        end = self.path[-1]
        remaining = math.hypot(end[0] - x, end[1] - y)
        beside = remaining < NEAR and abs(math.cos(math.atan2(end[1] - y, end[0] - x) - yaw)) < 0.5
        self.spinning = False
        if remaining < arrive_within or beside:  # at the goal, or next to it: no turning
            self.drive(0.0, 0.0)
            return True
        self.progress = self._project(x, y)
        gx, gy = self._point_at(self.progress + LOOKAHEAD)
        gx, gy = gx + float(self.offset[0]), gy + float(self.offset[1])
        alpha = math.atan2(gy - y, gx - x) - yaw
        alpha = math.atan2(math.sin(alpha), math.cos(alpha))
        if abs(alpha) > math.pi / 3:  # face the path first: turn on the spot
            self.spinning = True
            self.drive(0.0, math.copysign(MAX_TURN_RATE, alpha))
            return False
        distance = max(math.hypot(gx - x, gy - y), 1e-3)
        braking = math.sqrt(2.0 * DECEL * remaining)  # stop at the end, not before it
        speed = min(self.speed, braking, self.limit) * max(math.cos(alpha), 0.2)
        turn = max(-MAX_TURN_RATE, min(MAX_TURN_RATE, 2.0 * speed * math.sin(alpha) / distance))
        self.drive(speed, turn)
        return False
