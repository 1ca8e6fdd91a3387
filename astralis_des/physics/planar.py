"""Horizontal rays against the static axis-aligned boxes, in numpy.

A levelled lidar's beams lie in one horizontal plane, and the world's walls, slabs, obstacles
and furniture are axis-aligned boxes (``PhysicsClient.add_boxes``). Against those a beam is a
2-D slab test: cheaper in numpy for a whole scan than Bullet's convex cast per box a ray's
bounding volume meets. The lidar then asks Bullet only along the beams that cross the bounding
box of another body (robots, avatars, the target, imported meshes), and only as far as each
beam's box. (Putting the boxes in a collision group of their own, for a ray mask to leave them
out, slowed every physics step by a quarter.)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from astralis_des.world.geometry import FloatArray

__all__ = ["BoxIndex", "crossings", "cut", "inverse"]

TINY = 1e-12  # a direction component smaller than this is taken as this (no 0 / 0)


def crossings(lo: FloatArray, hi: FloatArray, centre: FloatArray, directions: FloatArray,
              start: float, stop: float | FloatArray, inside: bool = False) -> FloatArray:
    """Where each horizontal ray ``centre + t * direction``, ``t`` in ``[start, stop]``, enters
    each box (``lo``/``hi`` rows, only their x and y used): an array of boxes x rays, ``inf``
    where it misses. A ray starting inside a box misses it, as in Bullet, unless ``inside``:
    then it enters at ``start``."""
    x, y = float(centre[0]), float(centre[1])
    inv_x, inv_y = inverse(directions[:, :2].T)
    # where each ray crosses each box's x and y faces; inside both slabs is inside the box
    t_x0 = (lo[:, 0] - x)[:, None] * inv_x
    t_x1 = (hi[:, 0] - x)[:, None] * inv_x
    t_y0 = (lo[:, 1] - y)[:, None] * inv_y
    t_y1 = (hi[:, 1] - y)[:, None] * inv_y
    # the same minima and maxima, written over arrays done with (a scan's are boxes x 360)
    enter = np.minimum(t_x0, t_x1)
    leave = np.maximum(t_x0, t_x1, out=t_x0)
    np.maximum(enter, np.minimum(t_y0, t_y1, out=t_x1), out=enter)
    np.minimum(leave, np.maximum(t_y0, t_y1, out=t_y0), out=leave)
    if inside:
        np.maximum(enter, start, out=enter)
    enter[(enter < start) | (enter > leave) | (enter > stop)] = np.inf
    return enter


def inverse(dirs: FloatArray) -> FloatArray:
    """``1 / dirs``, a component under ``TINY`` taken as ``TINY`` of its sign."""
    with np.errstate(divide="ignore"):
        inv = 1.0 / dirs
    tiny = np.abs(dirs) < TINY
    if tiny.any():
        inv[tiny] = 1.0 / np.copysign(TINY, dirs[tiny])
    return inv


def cut(lo: FloatArray, hi: FloatArray, centre: FloatArray, reach: float) -> NDArray[np.intp]:
    """The boxes the rays' plane cuts within ``reach`` of their centre."""
    x, y, z = (float(v) for v in centre)
    gap_x = np.maximum(np.maximum(lo[:, 0] - x, x - hi[:, 0]), 0.0)
    gap_y = np.maximum(np.maximum(lo[:, 1] - y, y - hi[:, 1]), 0.0)
    return np.flatnonzero((lo[:, 2] <= z) & (z <= hi[:, 2])
                          & (gap_x * gap_x + gap_y * gap_y <= reach * reach))


class BoxIndex:
    """The static axis-aligned boxes of a client and the body holding each."""

    def __init__(self) -> None:
        self.lo: FloatArray = np.empty((0, 3))
        self.hi: FloatArray = np.empty((0, 3))
        self.body: NDArray[np.int32] = np.empty(0, dtype=np.int32)
        self.bodies: set[int] = set()

    def __len__(self) -> int:
        return len(self.body)

    def add(self, lo: FloatArray, hi: FloatArray, body: int) -> None:
        """Boxes given by their corners, held by ``body``."""
        self.lo = np.vstack([self.lo, lo])
        self.hi = np.vstack([self.hi, hi])
        self.body = np.concatenate([self.body, np.full(len(lo), body, dtype=np.int32)])
        self.bodies.add(body)

    def cast(self, centre: FloatArray, directions: FloatArray, start: float,
             stop: float) -> tuple[FloatArray, NDArray[np.int32]]:
        """The nearest box along each horizontal ray from ``start`` to ``stop``: its distance
        and body, or ``inf`` and -1 where the ray meets none."""
        rays = len(directions)
        near = cut(self.lo, self.hi, centre, stop)
        if len(near) == 0:
            return np.full(rays, np.inf), np.full(rays, -1, dtype=np.int32)
        enter = crossings(self.lo[near], self.hi[near], centre, directions, start, stop)
        nearest = np.argmin(enter, axis=0)
        t = enter[nearest, np.arange(rays)]
        body = np.where(np.isfinite(t), self.body[near][nearest], -1).astype(np.int32)
        return t, body
