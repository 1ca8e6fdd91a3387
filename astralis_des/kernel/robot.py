"""A robot: its kind, parameters, task handler, and where it is at any simulated time."""

from __future__ import annotations

from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol, TypeVar, runtime_checkable

import numpy as np

from astralis_des.kernel.course import Course, course_of
from astralis_des.kernel.profile import Profile
from astralis_des.world.geometry import FloatArray

T = TypeVar("T")

if TYPE_CHECKING:
    from astralis_des.kernel.handler import TaskHandler
    from astralis_des.view import View


@runtime_checkable
class Trajectory(Protocol):
    """What a robot follows from ``t0``, as the kernel reads it: a kinematic :class:`Motion`,
    or a simulated body's track (the physics fidelity's ``Track``)."""

    t0: float

    def at(self, t: float) -> FloatArray: ...
    def travelled(self, t: float) -> float: ...
    def heading_at(self, t: float, before: float) -> float: ...
    def vertices_until(self, t: float) -> tuple[FloatArray, FloatArray]: ...


@dataclass
class Motion:
    """A path followed from ``t0`` under a speed profile (:mod:`.profile`): cruise at
    ``speed``; with ``accel``, speed up, slow down at corners and stop at the end; with
    ``turn_rate``, turn on the spot from ``heading`` at each vertex. Poses are interpolated
    on demand."""

    points: FloatArray
    speed: float
    t0: float = 0.0
    accel: float | None = None
    turn_rate: float | None = None
    heading: float = 0.0
    cum: FloatArray = field(init=False)
    profile: Profile = field(init=False)
    _course: Course = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        self.points = np.asarray(self.points, dtype=float)
        self._course = course_of(self.points, self.speed, self.accel, self.turn_rate,
                                 self.heading)
        self.cum = self._course.cum
        self.profile = self._course.profile

    @property
    def length(self) -> float:
        return float(self.cum[-1])

    @property
    def duration(self) -> float:
        return self.profile.duration

    def _point(self, s: float) -> FloatArray:
        return np.array(self._course.point(s))

    def at(self, t: float) -> FloatArray:
        return self._point(self.profile.arc_at(t - self.t0))

    def velocity(self, t: float) -> FloatArray:
        """The reference velocity at ``t``: the profile's speed along the current leg."""
        s = float(self.profile.arc(t - self.t0))
        k = min(max(int(np.searchsorted(self.cum, s, side="right")), 1), len(self.cum) - 1)
        leg = self.points[k] - self.points[k - 1]
        norm = float(np.linalg.norm(leg))
        return leg / norm * self.profile.speed(t - self.t0) if norm > 1e-9 else np.zeros(3)

    def sample(self, times: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Reference positions and velocities at many times at once: ``(N, 3)`` each."""
        dt = np.asarray(times, dtype=float) - self.t0
        s = self.profile.arc(dt)
        pos = np.column_stack([np.interp(s, self.cum, self.points[:, k]) for k in range(3)])
        if len(self.points) < 2:  # a path of one point: there, still
            return pos, np.zeros_like(pos)
        legs = np.diff(self.points, axis=0)
        norms = np.linalg.norm(legs, axis=1)
        unit = np.divide(legs, norms[:, None], out=np.zeros_like(legs), where=norms[:, None] > 0)
        k = np.clip(np.searchsorted(self.cum, s, side="right"), 1, len(self.cum) - 1) - 1
        return pos, unit[k] * self.profile.speeds(dt)[:, None]

    def travelled(self, t: float) -> float:
        return self.profile.arc_at(t - self.t0)

    def time_of(self, s: FloatArray) -> FloatArray:
        """Seconds after the start at which each arc length in ``s`` is reached."""
        return self.profile.time_of(s)

    def heading_at(self, t: float, before: float) -> float:
        """The heading after running until ``t``: that of the last leg begun that moves
        horizontally (the turned-to heading for a robot that turns on the spot)."""
        return self._course.heading_at(self.profile.arc_at(t - self.t0), before,
                                       self.turn_rate is not None)

    def derived(self, key: Hashable, make: Callable[[], T]) -> T:
        """What ``make`` derives from the path and the parameters alone (and ``key``): made
        once for every motion along the same course (:class:`.course.Course`)."""
        return self._course.derived(key, make)

    def vertices_until(self, t: float) -> tuple[FloatArray, FloatArray]:
        """Timed vertices passed by time ``t``, plus the pose at ``t``: ``(times, points)``."""
        times = self.t0 + self._course.vertex_times()
        if self._course.in_order:  # those passed are the first k
            k = int(times.searchsorted(t))
            passed_t, passed_p = times[:k], self.points[:k]
        else:
            keep = times < t
            passed_t, passed_p = times[keep], self.points[keep]
        k = len(passed_t)
        out_t, out_p = np.empty(k + 1), np.empty((k + 1, self.points.shape[1]))
        out_t[:k], out_t[k] = passed_t, t
        out_p[:k], out_p[k] = passed_p, self._course.point(self.profile.arc_at(t - self.t0))
        return out_t, out_p


@dataclass
class Robot:
    id: str
    kind: str
    speed: float
    view: View | None  # its camera's field of view; None: it carries no camera
    height: float
    pose: FloatArray
    handler: TaskHandler | None = None
    motion: Trajectory | None = None
    faulted: bool = False
    accel: float | None = None  # m/s^2; None: starts and stops at once
    turn_rate: float | None = None  # rad/s on the spot, for a non-holonomic robot
    heading: float = 0.0
    airborne: bool = True  # false for a UAV on the ground: it takes off before it moves
    distance: float = 0.0
    busy_time: float = 0.0
    trail_t: list[float] = field(default_factory=list)
    trail_p: list[FloatArray] = field(default_factory=list)
    plans: list[tuple[float, FloatArray]] = field(default_factory=list)  # (start, path) a leg
    # each kinematic motion as it ran: (start, end, motion, heading at the end), for poses
    # at any past time (pose sensors)
    history: list[tuple[float, float, Motion, float]] = field(default_factory=list)

    def position(self, now: float) -> FloatArray:
        return self.motion.at(now) if self.motion is not None else self.pose

    def begin(self, motion: Trajectory, now: float) -> None:
        self.halt(now)
        motion.t0 = now
        self.motion = motion

    def halt(self, now: float) -> None:
        """End the current motion where the robot is now, and book its distance and trail."""
        if self.motion is None:
            return
        times, pts = self.motion.vertices_until(now)
        if isinstance(self.motion, Motion):  # a body's heading is its own (it faces, turns)
            self.heading = self.motion.heading_at(now, self.heading)
            self.history.append((self.motion.t0, now, self.motion, self.heading))
        self.trail_t.extend(times.tolist())
        self.trail_p.extend(pts)
        self.distance += self.motion.travelled(now)
        self.pose = pts[-1]
        self.motion = None
