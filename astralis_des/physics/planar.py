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

__all__ = ["BoxIndex", "crossings", "cut", "nearest_crossings"]

TINY = 1e-12  # a direction component smaller than this is taken as this (no 0 / 0)
SLACK = 1e-7  # rad added to each side of a box's angular window (a ray's direction is exact
# to about 1e-12 rad: TINY's stand-in components)


def crossings(lo: FloatArray, hi: FloatArray, centre: FloatArray, directions: FloatArray,
              start: float, stop: float | FloatArray, inside: bool = False) -> FloatArray:
    """Where each horizontal ray ``centre + t * direction``, ``t`` in ``[start, stop]``, enters
    each box (``lo``/``hi`` rows, only their x and y used): an array of boxes x rays, ``inf``
    where it misses. A ray starting inside a box misses it, as in Bullet, unless ``inside``:
    then it enters at ``start``."""
    inv_x, inv_y = _inverse(directions)
    return _enter(lo[:, 0, None], hi[:, 0, None], lo[:, 1, None], hi[:, 1, None], centre,
                  inv_x, inv_y, start, stop, inside)


def _inverse(directions: FloatArray) -> tuple[FloatArray, FloatArray]:
    dx, dy = directions[:, 0], directions[:, 1]
    inv_x = 1.0 / np.where(np.abs(dx) < TINY, np.copysign(TINY, dx), dx)
    inv_y = 1.0 / np.where(np.abs(dy) < TINY, np.copysign(TINY, dy), dy)
    return inv_x, inv_y


def _enter(lo_x: FloatArray, hi_x: FloatArray, lo_y: FloatArray, hi_y: FloatArray,
           centre: FloatArray, inv_x: FloatArray, inv_y: FloatArray, start: float,
           stop: float | FloatArray, inside: bool) -> FloatArray:
    """The slab test, element by element (boxes and rays broadcast against each other)."""
    x, y = float(centre[0]), float(centre[1])
    # where each ray crosses each box's x and y faces; inside both slabs is inside the box
    t_x0 = (lo_x - x) * inv_x
    t_x1 = (hi_x - x) * inv_x
    t_y0 = (lo_y - y) * inv_y
    t_y1 = (hi_y - y) * inv_y
    enter = np.maximum(np.minimum(t_x0, t_x1), np.minimum(t_y0, t_y1))
    leave = np.minimum(np.maximum(t_x0, t_x1), np.maximum(t_y0, t_y1))
    if inside:
        np.maximum(enter, start, out=enter)
    enter[(enter < start) | (enter > leave) | (enter > stop)] = np.inf
    return enter


def nearest_crossings(lo: FloatArray, hi: FloatArray, centre: FloatArray,
                      directions: FloatArray, start: float,
                      stop: float) -> tuple[FloatArray, NDArray[np.intp]]:
    """For each horizontal ray, the nearest box it enters (as :func:`crossings`) and that
    box's row: ``inf`` and -1 where it enters none; of boxes entered at the same distance,
    the first row. :func:`crossings`' own array and nearest, computed only along the rays
    that can meet each box: those within the angle its corners span from ``centre`` (every
    ray, for a box whose footprint holds the centre); the others miss it (``inf``) there too."""
    rays = len(directions)
    if not len(lo) or not rays:
        return np.full(rays, np.inf), np.full(rays, -1, dtype=np.intp)
    x, y = float(centre[0]), float(centre[1])
    angle = np.arctan2(directions[:, 1], directions[:, 0])
    order = np.argsort(angle, kind="stable")
    around = np.concatenate([angle[order], angle[order] + 2 * np.pi])  # a window may wrap
    corners_x = np.stack([lo[:, 0], hi[:, 0], hi[:, 0], lo[:, 0]], axis=1) - x
    corners_y = np.stack([lo[:, 1], lo[:, 1], hi[:, 1], hi[:, 1]], axis=1) - y
    mid = np.arctan2(corners_y.mean(axis=1), corners_x.mean(axis=1))
    offs = np.remainder(np.arctan2(corners_y, corners_x) - mid[:, None] + np.pi,
                        2 * np.pi) - np.pi
    first = np.remainder(mid + offs.min(axis=1) - SLACK + np.pi, 2 * np.pi) - np.pi
    span = offs.max(axis=1) - offs.min(axis=1) + 2 * SLACK
    begin = np.searchsorted(around, first, side="left")
    end = np.searchsorted(around, first + span, side="right")
    holds = (lo[:, 0] <= x) & (x <= hi[:, 0]) & (lo[:, 1] <= y) & (y <= hi[:, 1])
    begin[holds], end[holds] = 0, rays
    counts = np.minimum(end - begin, rays)
    box = np.repeat(np.arange(len(lo)), counts)
    at = np.arange(len(box)) - np.repeat(np.cumsum(counts) - counts, counts)
    ray = np.concatenate([order, order])[np.repeat(begin, counts) + at]
    inv_x, inv_y = _inverse(directions)
    enter = np.full((len(lo), rays), np.inf)
    enter[box, ray] = _enter(lo[box, 0], hi[box, 0], lo[box, 1], hi[box, 1], centre,
                             inv_x[ray], inv_y[ray], start, stop, False)
    nearest = np.argmin(enter, axis=0)
    t = enter[nearest, np.arange(rays)]
    return t, np.where(np.isfinite(t), nearest, -1)


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
        t, nearest = nearest_crossings(self.lo[near], self.hi[near], centre, directions, start,
                                       stop)
        body = np.where(nearest >= 0, self.body[near][nearest], -1).astype(np.int32)
        return t, body
