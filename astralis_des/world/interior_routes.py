"""Routes inside an interior's places, which need not be convex (an L-shaped hall, a corridor
round a block of rooms): a visibility graph per place, of its seat, the inner side of each of
its doors and its reflex corners (moved ``CORNER`` m inwards, so that a body keeps off them),
two of them joined where the straight line between them stays inside the place's outline. In
a rectangle every two see each other, as in a built-in room or corridor.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from astralis_des.world.geometry import FloatArray, cross2, inside_polygon
from astralis_des.world.parts import Door, InteriorPlan

CORNER = 0.8  # m from a reflex corner, inwards, where a route turns round it: clear of both
# walls by a UGV's half width and its rim
APART = 0.3  # m: corners nearer than this to one kept already are the same turn


def reflex_corners(outline: FloatArray, inset: float = CORNER) -> FloatArray:
    """``(K, 2)``: the outline's reflex corners (its inside angle over 180 degrees), each moved
    ``inset`` inwards along the bisector of its sides; those that land outside are dropped."""
    p = np.asarray(outline, dtype=float)
    if len(p) < 4:
        return np.zeros((0, 2))
    before, after = np.roll(p, 1, axis=0), np.roll(p, -1, axis=0)
    area = float(np.sum(p[:, 0] * after[:, 1] - after[:, 0] * p[:, 1]))  # twice, signed
    turn = cross2(p - before, after - p)
    reflex = turn * np.sign(area) < -1e-12
    back = _unit(before - p) + _unit(after - p)
    inward = -_unit(back)
    points = (p + inset * inward)[reflex & (np.linalg.norm(back, axis=1) > 1e-9)]
    points = points[inside_polygon(points, p)] if len(points) else points
    kept: list[FloatArray] = []
    for q in points:
        if all(np.hypot(*(q - k)) >= APART for k in kept):
            kept.append(q)
    return np.array(kept).reshape(-1, 2)


def visible(a: FloatArray, b: FloatArray, outline: FloatArray) -> NDArray[np.bool_]:
    """``(M,)``: does the segment ``a[m] -> b[m]`` stay inside ``outline`` (it crosses none of
    its sides and its middle is inside)?"""
    a, b = np.atleast_2d(np.asarray(a, dtype=float)), np.atleast_2d(np.asarray(b, dtype=float))
    e0 = np.asarray(outline, dtype=float)
    e1 = np.roll(e0, -1, axis=0)
    d1, d2 = _side(a, b, e0), _side(a, b, e1)  # (M, E): the sides' ends about each segment
    d3 = _side(e0[None], e1[None], a[:, None]) if len(a) else np.zeros((0, len(e0)))
    d4 = _side(e0[None], e1[None], b[:, None]) if len(b) else np.zeros((0, len(e0)))
    crosses = ((d1 * d2) < 0) & ((d3 * d4) < 0)
    return np.asarray(~crosses.any(axis=1) & inside_polygon((a + b) / 2, e0))


def side_of(plan: InteriorPlan, place: str | None, door: Door, step: float) -> float:
    """Which way along the door's axis (+1 or -1) ``place`` lies: where a point ``step``
    through the door is inside its outline, else towards its seat."""
    assert place is not None  # a door's first place is a place; only the second may be out
    axis, outline = door.normal_axis, np.asarray(plan.outlines[place], dtype=float)
    for sign in (1.0, -1.0):
        probe = np.array(door.center[:2], dtype=float)
        probe[axis] += sign * step
        if inside_polygon(probe[None, :], outline)[0]:
            return sign
    return math.copysign(1.0, plan.seats[place][axis] - door.center[axis])


def _side(a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
    """The sign of the turn ``a -> b -> c``, broadcast: ``a``, ``b`` ``(M, 2)`` or
    ``(1, E, 2)``, ``c`` ``(E, 2)`` or ``(M, 1, 2)``."""
    if a.ndim == 2:
        a, b = a[:, None, :], b[:, None, :]
        c = c[None, :, :]
    cross = (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - \
        (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])
    return np.asarray(np.where(np.abs(cross) < 1e-12, 0.0, np.sign(cross)))


def _unit(v: FloatArray) -> FloatArray:
    n = np.linalg.norm(v, axis=1, keepdims=True)
    return np.asarray(np.where(n > 1e-12, v / np.maximum(n, 1e-12), 0.0))
