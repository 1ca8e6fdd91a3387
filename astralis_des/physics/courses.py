"""The bodies the local layer sees, and where they will meet: helpers of the local layer and
of a UAV's climbs."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from astralis_des.physics.drivers import SAMPLE
from astralis_des.world.geometry import FloatArray

LOOK_AHEAD = 0.8  # s: where the others will be, for the lane test


@dataclass
class Body:
    """Something the local layer avoids: a robot, a mover or the moving lift."""

    name: str
    kind: str  # a robot kind, or what a mover is (avatar, obstacle), or "lift"
    xy: FloatArray
    velocity: FloatArray  # xy: zero while it holds
    z: tuple[float, float]
    radius: float  # how far it reaches ahead and behind (a disc round it)
    rank: int  # lower yields to higher; movers rank above every robot
    base_z: tuple[float, float] = (0.0, 0.0)  # a UAV's band before any climb
    offset: FloatArray = field(default_factory=lambda: np.zeros(2))  # its shift off its path
    half_width: float = 0.0  # how far it reaches to the side (a long body's less than radius)

    def __post_init__(self) -> None:
        self.half_width = self.half_width or self.radius


def on_route(route: FloatArray, xy: FloatArray, velocity: FloatArray) -> tuple[float, float]:
    """How far along ``route`` a body at ``xy`` (or where it will be in ``LOOK_AHEAD`` s)
    comes nearest to it, and how near: ``(metres along, metres off)``."""
    best_along, best_off = math.inf, math.inf
    for where in (xy, xy + velocity * LOOK_AHEAD):
        d = np.linalg.norm(route - where, axis=1)
        i = int(np.argmin(d))
        if d[i] < best_off:
            best_along, best_off = i * SAMPLE, float(d[i])
    return best_along, best_off


def closest_approach(rel: FloatArray, velocity: FloatArray, horizon: float) -> float:
    """The least distance over the next ``horizon`` s of a body at ``rel`` moving at
    ``velocity`` relative to a still observer."""
    speed2 = float(velocity @ velocity)
    t = 0.0 if speed2 < 1e-9 else min(max(-float(rel @ velocity) / speed2, 0.0), horizon)
    return float(np.linalg.norm(rel + velocity * t))
