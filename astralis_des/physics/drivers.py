"""Drivers: each robot kind's body and controller behind one interface for the stepper.

``start(motion, t)`` begins a motion; ``tick(t)`` applies the commands for the next control
period and returns ``None`` while the motion goes on, else ``"arrived"``; ``position()`` is
the robot's pose (its sensor's position, as in the kinematic fidelity); ``progress()`` is how
far along its path it has got (metres), which the stepper's stuck test watches; ``crashed()``
says why the body is down, if it is. The UAV's and the UGV's drivers live in their own
modules and register here.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

import numpy as np

from astralis_des.kernel.robot import Motion, Robot
from astralis_des.mission.spec import PhysicsSpec
from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.walker import Walker
from astralis_des.registry import Registry
from astralis_des.world.geometry import FloatArray

SHIFT_RATE = 1.2  # m/s: how fast a robot moves aside to keep right, or back
ARRIVED = 0.2  # m: the default "close enough" to the end of a path
SAMPLE = 0.2  # m between the points of a path ahead


class Driver(Protocol):
    """A robot's body and controller. What only some bodies can do is declared here and
    answered by each: ``turn_to`` (False: it faces any way at once), ``course_z`` (None: it
    flies no reference course), ``blocked_by`` (empty but for a walker that waits)."""

    body: int
    held: bool
    shift: FloatArray
    arrive_within: float
    blocked_by: tuple[str, ...]  # the robots it last had to wait for

    def turn_to(self, heading: float) -> bool: ...
    def course_z(self) -> float | None: ...

    def start(self, motion: Motion, t: float) -> None: ...
    def tick(self, t: float) -> str | None: ...
    def position(self) -> FloatArray: ...
    def freeze(self) -> None: ...
    def wake(self) -> None: ...
    def heading_vector(self) -> FloatArray: ...
    def progress(self) -> float: ...
    def path_ahead(self, distance: float) -> FloatArray: ...
    def goal_point(self) -> FloatArray: ...
    def avoid(self, hold: bool, shift: FloatArray, climb: float = 0.0) -> None: ...
    def slow_down(self, share: float) -> None: ...
    def crashed(self) -> str | None: ...
    def fall(self, floor: FloatArray) -> None: ...
    def recover(self, at: FloatArray) -> None: ...


DriverClass = Callable[[PhysicsClient, Robot, PhysicsSpec, Path], Driver]
"""How a driver is built: ``DRIVERS.get(kind)(client, robot, spec, urdf)``."""

DRIVERS: Registry[str, type] = Registry(
    "driver", plugins=("astralis_des.physics.uav_driver", "astralis_des.physics.ugv_driver"))


class Avoiding:
    """What the local layer sets on a driver: hold still, how far to stand aside (and, for a
    UAV, to climb), and how near its goal counts as there (farther when another body stands
    on it)."""

    held: bool = False
    shift: FloatArray
    shift_to: FloatArray
    shift_rate: float = SHIFT_RATE
    lift_z: float = 0.0
    lift_to: float = 0.0
    arrive_within: float = ARRIVED
    blocked_by: tuple[str, ...] = ()  # the robots it last had to wait for (a walker's)

    def _clear_avoidance(self) -> None:
        self.held = False
        self.shift = np.zeros(2)
        self.shift_to = np.zeros(2)
        self.lift_z = self.lift_to = 0.0
        self.arrive_within = ARRIVED

    def avoid(self, hold: bool, shift: FloatArray, climb: float = 0.0) -> None:
        self.held, self.shift_to, self.lift_to = hold, np.asarray(shift, dtype=float), climb

    def slow_down(self, share: float) -> None:
        """Obstacles ahead (the lidar): go at most ``share`` of the speed. Only a UGV does."""

    def turn_to(self, heading: float) -> bool:
        """Turn on the spot to ``heading``: False, it faces any way at once. Only a UGV turns."""
        return False

    def course_z(self) -> float | None:
        """The height its reference flies at now: None, it flies none. Only a UAV does."""
        return None

    def wake(self) -> None:
        """Something is about to touch it while it stands idle: a body asleep in Bullet
        answers again. Only a UGV sleeps (``physics.sleep_idle``)."""


class PlacedBody(Protocol):
    """A body a :class:`PlacedDriver` puts where it should be each control period."""

    body: int
    centre_height: float  # m from the floor to its centre

    def __init__(self, client: PhysicsClient, centre: FloatArray) -> None: ...
    def place(self, centre: FloatArray, yaw: float) -> None: ...
    def position(self) -> FloatArray: ...


class PlacedDriver(Avoiding):
    """Follows the path at its speed, kinematically: its body (``body_class``) placed at each
    tick, never into another robot's body (it waits instead). A person's driver; a plug-in's
    kind whose gait is not simulated (``examples/plugins/legged.py``) subclasses it with its
    own body."""

    body_class: type[PlacedBody] = Walker
    turns = False  # its body is turned to the way it goes (a person's capsule need not be)

    def __init__(self, client: PhysicsClient, robot: Robot, spec: PhysicsSpec, urdf: Path) -> None:
        self.client = client
        self.centre_height = self.body_class.centre_height
        self.offset = np.array([0.0, 0.0, robot.height - self.centre_height])
        self.period = 1.0 / spec.control_rate
        self.walker = self.body_class(client, robot.pose - self.offset)
        self.yaw = robot.heading  # rad: where its body faces (the way it last went)
        self.body = self.walker.body
        self.placed = np.asarray(robot.pose - self.offset, dtype=float)
        self.motion: Motion | None = None
        # the bodies of the robots near a point (set by the co-simulation): a walker is
        # placed, not pushed, so it must not step into one of them
        self.bodies_near: Callable[[FloatArray], list[int]] = lambda point: []
        self.robot_of: dict[int, str] = {}  # body -> robot id, for the bodies above
        self.blocked_by: tuple[str, ...] = ()  # the robots it last had to wait for
        self._clear_avoidance()

    def start(self, motion: Motion, t: float) -> None:
        self.motion = motion
        self.elapsed = 0.0  # walking time so far: it stops while the walker waits
        self._clear_avoidance()

    def heading_vector(self) -> FloatArray:
        if self.motion is None:
            return np.zeros(2)
        return np.asarray(self.motion.velocity(self.motion.t0 + self.elapsed)[:2])

    def progress(self) -> float:
        return 0.0 if self.motion is None else self.motion.travelled(
            self.motion.t0 + self.elapsed)

    def path_ahead(self, distance: float) -> FloatArray:
        if self.motion is None:
            return self.position()[None, :]
        return samples_along(self.motion.points, self.motion.cum, self.progress(), distance)

    def goal_point(self) -> FloatArray:
        return self.position() if self.motion is None else np.asarray(self.motion.points[-1])

    def tick(self, t: float) -> str | None:
        assert self.motion is not None
        before = (self.elapsed, self.shift, self.placed)
        if not self.held:
            self.elapsed += self.period
        self.shift = ramp(self.shift, self.shift_to, self.shift_rate * self.period)
        where = self.motion.at(self.motion.t0 + self.elapsed) - self.offset
        where[:2] += self.shift
        near = self.bodies_near(where)
        depth = self._overlap(near)
        if self.turns:
            self._face()
        self.walker.place(where, self.yaw)
        self.placed = where
        self.blocked_by = ()
        if near and self._overlap(near) > depth + 1e-4:  # it would step into a robot: wait
            self.elapsed, self.shift, self.placed = before
            self.walker.place(self.placed, self.yaw)
            self.blocked_by = tuple(self.robot_of.get(b, "") for b in near)
        if self.elapsed >= self.motion.duration:
            return "arrived"
        remaining = self.motion.length - self.progress()
        if self.held and remaining < ARRIVED:  # held a step from its goal: it is there
            return "arrived"
        return "arrived" if remaining < self.arrive_within - ARRIVED else None

    def _face(self) -> None:
        """Turn to the way it goes now (where it stands still, the way it last went)."""
        dx, dy = (float(v) for v in self.heading_vector())
        if dx * dx + dy * dy > 1e-12:
            self.yaw = math.atan2(dy, dx)

    def _overlap(self, bodies: list[int]) -> float:
        """How deep the walker is in any of ``bodies`` where it stands now (0 if in none)."""
        deepest = 0.0
        for body in bodies:
            for c in self.client.call("getClosestPoints", self.body, body, 0.0):
                deepest = max(deepest, -float(c[8]))
        return deepest

    def position(self) -> FloatArray:
        return self.walker.position() + self.offset

    def crashed(self) -> str | None:
        """A walker is placed, not simulated: it does not fall."""
        return None

    def fall(self, floor: FloatArray) -> None:
        """A walker does not crash."""

    def recover(self, at: FloatArray) -> None:
        self.walker.place(at + np.array([0.0, 0.0, self.centre_height]), self.yaw)

    def freeze(self) -> None:
        """A walker is kinematic: standing still costs nothing."""


@DRIVERS.register("human")
class HumanDriver(PlacedDriver):
    """Walks the path at its speed, kinematically: a capsule placed at each tick."""


def ramp(current: FloatArray, target: FloatArray, step: float) -> FloatArray:
    """Move ``current`` towards ``target`` by at most ``step`` (plain floats: every tick)."""
    (tx, ty), (cx, cy) = target.tolist(), current.tolist()
    dx, dy = tx - cx, ty - cy
    if dx == 0.0 and dy == 0.0:
        return current
    norm = (dx * dx + dy * dy) ** 0.5
    if norm <= step:
        return np.array([tx, ty])
    k = step / norm
    return np.array([cx + dx * k, cy + dy * k])


def samples_along(points: FloatArray, cum: FloatArray, start: float,
                  distance: float) -> FloatArray:
    """Points of the polyline ``points`` (arc lengths ``cum``) from arc length ``start`` to
    ``start + distance``, ``SAMPLE`` apart, both ends included."""
    end = min(start + distance, float(cum[-1]))
    s = np.append(np.arange(start, end, SAMPLE), end)
    return np.column_stack([np.interp(s, cum, points[:, k]) for k in range(points.shape[1])])

