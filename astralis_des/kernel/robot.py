"""A robot: its kind, parameters, task handler, and where it is at any simulated time."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.world.geometry import FloatArray

if TYPE_CHECKING:
    from astralis_des.kernel.handler import TaskHandler


@dataclass
class Motion:
    """A path followed at constant speed from ``t0``; the pose is interpolated on demand.

    With a ``turn_rate`` (a non-holonomic robot) it first turns on the spot at each vertex,
    from ``heading`` to the direction of the next leg.
    """

    points: FloatArray
    speed: float
    t0: float = 0.0
    turn_rate: float | None = None
    heading: float = 0.0
    cum: FloatArray = field(init=False)
    knots: FloatArray = field(init=False)  # time since t0 of each entry of ``stops``
    stops: FloatArray = field(init=False)  # vertices, repeated where the robot turns
    stop_cum: FloatArray = field(init=False)

    def __post_init__(self) -> None:
        self.points = np.asarray(self.points, dtype=float)
        seg = np.linalg.norm(np.diff(self.points, axis=0), axis=1) if len(self.points) > 1 \
            else np.zeros(0)
        self.cum = np.concatenate([[0.0], np.cumsum(seg)])
        legs = seg / self.speed
        if self.turn_rate is None:
            self.knots = np.concatenate([[0.0], np.cumsum(legs)])
            self.stops, self.stop_cum = self.points, self.cum
            return
        heading, t = self.heading, 0.0
        knots, stops, cums = [0.0], [self.points[0]], [0.0]
        for i, length in enumerate(seg):
            d = self.points[i + 1] - self.points[i]
            if length > 1e-6 and math.hypot(d[0], d[1]) > 1e-6:
                want = math.atan2(d[1], d[0])
                t += abs(math.remainder(want - heading, math.tau)) / self.turn_rate
                heading = want
                knots.append(t)
                stops.append(self.points[i])
                cums.append(self.cum[i])
            t += legs[i]
            knots.append(t)
            stops.append(self.points[i + 1])
            cums.append(self.cum[i + 1])
        self.end_heading = heading
        self.knots, self.stops, self.stop_cum = np.array(knots), np.array(stops), np.array(cums)

    @property
    def length(self) -> float:
        return float(self.cum[-1])

    @property
    def duration(self) -> float:
        return float(self.knots[-1])

    def at(self, t: float) -> FloatArray:
        dt = t - self.t0
        return np.array([np.interp(dt, self.knots, self.stops[:, k]) for k in range(3)])

    def travelled(self, t: float) -> float:
        return float(np.interp(t - self.t0, self.knots, self.stop_cum))

    def heading_at(self, t: float, before: float) -> float:
        """The heading once the motion has run until ``t`` (``before``: at its start)."""
        if self.turn_rate is None or t - self.t0 < self.duration:
            return before if self.turn_rate is None else self._heading_before(t - self.t0,
                                                                              before)
        return self.end_heading

    def _heading_before(self, dt: float, heading: float) -> float:
        for i in range(len(self.stops) - 1):
            if self.knots[i] > dt:
                break
            d = self.stops[i + 1] - self.stops[i]
            if math.hypot(d[0], d[1]) > 1e-6:
                heading = math.atan2(d[1], d[0])
        return heading

    def vertices_until(self, t: float) -> tuple[FloatArray, FloatArray]:
        """Timed vertices passed by time ``t``, plus the pose at ``t``: ``(times, points)``."""
        times = self.t0 + self.knots
        keep = times < t
        pts = np.vstack([self.stops[keep], self.at(t)[None, :]])
        return np.append(times[keep], t), pts


@dataclass
class Robot:
    id: str
    kind: str
    speed: float
    detection_radius: float
    height: float
    pose: FloatArray
    handler: TaskHandler | None = None
    motion: Motion | None = None
    faulted: bool = False
    turn_rate: float | None = None  # rad/s on the spot, for a non-holonomic robot
    heading: float = 0.0
    distance: float = 0.0
    busy_time: float = 0.0
    trail_t: list[float] = field(default_factory=list)
    trail_p: list[FloatArray] = field(default_factory=list)

    def position(self, now: float) -> FloatArray:
        return self.motion.at(now) if self.motion is not None else self.pose

    def begin(self, motion: Motion, now: float) -> None:
        self.halt(now)
        motion.t0 = now
        self.motion = motion

    def halt(self, now: float) -> None:
        """End the current motion where the robot is now, and book its distance and trail."""
        if self.motion is None:
            return
        times, pts = self.motion.vertices_until(now)
        if isinstance(self.motion, Motion):
            self.heading = self.motion.heading_at(now, self.heading)
        self.trail_t.extend(times.tolist())
        self.trail_p.extend(pts)
        self.distance += self.motion.travelled(now)
        self.pose = pts[-1]
        self.motion = None
