"""A robot's motion in physics as the kernel sees it: its pose read from the body, its trail
and distance sampled as it goes, and the bookkeeping of the stuck test and the cap."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from astralis_des.physics.drivers import Driver
from astralis_des.world.geometry import FloatArray


@dataclass
class Track:
    """The motion of a robot in physics: its pose is read from the body; the trail and the
    distance are sampled as it goes."""

    driver: Driver
    t0: float
    cap: float  # s: the motion fails if it takes longer
    times: list[float] = field(default_factory=list)
    points: list[FloatArray] = field(default_factory=list)
    odometry: float = 0.0
    best: tuple[float, float] = (0.0, 0.0)  # the most progress made (m), and when

    def sample(self, t: float) -> FloatArray:
        here = self.driver.position()
        if self.points:
            self.odometry += float(np.linalg.norm(here - self.points[-1]))
        self.times.append(t)
        self.points.append(here)
        return here

    def at(self, t: float) -> FloatArray:
        return self.driver.position()

    def heading_at(self, t: float, before: float) -> float:
        """The way the body heads now (radians from +x)."""
        v = self.driver.heading_vector()
        return float(np.arctan2(v[1], v[0]))

    def travelled(self, t: float) -> float:
        return self.odometry + float(np.linalg.norm(self.driver.position() - self.points[-1]))

    def vertices_until(self, t: float) -> tuple[FloatArray, FloatArray]:
        return (np.append(self.times, t),
                np.vstack([*self.points, self.driver.position()[None, :]]))
