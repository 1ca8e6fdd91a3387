"""Where bodies will meet: helpers of the local layer and of a UAV's climbs."""

from __future__ import annotations

import math

import numpy as np

from astralis_des.physics.drivers import SAMPLE
from astralis_des.world.geometry import FloatArray

LOOK_AHEAD = 0.8  # s: where the others will be, for the lane test


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
