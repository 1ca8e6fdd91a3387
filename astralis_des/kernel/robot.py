"""A robot: its kind, parameters, task handler, and where it is at any simulated time."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.world.geometry import FloatArray

if TYPE_CHECKING:
    from astralis_des.kernel.handler import TaskHandler


@dataclass
class Motion:
    """A path followed at constant speed from ``t0``; the pose is interpolated on demand."""

    points: FloatArray
    speed: float
    t0: float = 0.0
    cum: FloatArray = field(init=False)

    def __post_init__(self) -> None:
        self.points = np.asarray(self.points, dtype=float)
        seg = np.linalg.norm(np.diff(self.points, axis=0), axis=1) if len(self.points) > 1 \
            else np.zeros(0)
        self.cum = np.concatenate([[0.0], np.cumsum(seg)])

    @property
    def length(self) -> float:
        return float(self.cum[-1])

    @property
    def duration(self) -> float:
        return self.length / self.speed

    def at(self, t: float) -> FloatArray:
        s = min(max(t - self.t0, 0.0) * self.speed, self.length)
        return np.array([np.interp(s, self.cum, self.points[:, k]) for k in range(3)])

    def travelled(self, t: float) -> float:
        return min(max(t - self.t0, 0.0) * self.speed, self.length)

    def vertices_until(self, t: float) -> tuple[FloatArray, FloatArray]:
        """Timed vertices passed by time ``t``, plus the pose at ``t``: ``(times, points)``."""
        times = self.t0 + self.cum / self.speed
        keep = times < t
        pts = np.vstack([self.points[keep], self.at(t)[None, :]])
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
        self.trail_t.extend(times.tolist())
        self.trail_p.extend(pts)
        self.distance += self.motion.travelled(now)
        self.pose = pts[-1]
        self.motion = None
