"""Axis-aligned boxes and vectorised segment tests against them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from astralis_des.compiled import kernels

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Box:
    """An axis-aligned box given by its two corners."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    @property
    def center(self) -> tuple[float, float, float]:
        return (
            (self.lo[0] + self.hi[0]) / 2, (self.lo[1] + self.hi[1]) / 2,
            (self.lo[2] + self.hi[2]) / 2,
        )

    @property
    def size(self) -> tuple[float, float, float]:
        return (self.hi[0] - self.lo[0], self.hi[1] - self.lo[1], self.hi[2] - self.lo[2])

    def contains(self, point: FloatArray | tuple[float, ...], margin: float = 0.0) -> bool:
        p = np.asarray(point, dtype=float)
        return bool(np.all(p >= np.asarray(self.lo) - margin)
                    and np.all(p <= np.asarray(self.hi) + margin))


def boxes_array(boxes: list[Box]) -> FloatArray:
    """``(K, 2, 3)`` array of box corners."""
    if not boxes:
        return np.zeros((0, 2, 3))
    return np.array([[b.lo, b.hi] for b in boxes], dtype=float)


JOINT = 4096  # segments times boxes up to which the slabs of all three axes are taken at once


def segments_hit_boxes(p0: FloatArray, p1: FloatArray, boxes: FloatArray) -> NDArray[np.bool_]:
    """``(M,)`` mask: does segment ``p0[m] -> p1[m]`` pass through any of ``boxes``?

    Slab test, vectorised over segments and boxes; touching a face counts as a hit.
    """
    p0 = np.atleast_2d(np.asarray(p0, dtype=float))
    p1 = np.atleast_2d(np.asarray(p1, dtype=float))
    if len(boxes) == 0 or len(p0) == 0:
        return np.zeros(len(p0), dtype=bool)
    compiled = kernels()
    if compiled is not None and p0.shape == p1.shape and p0.shape[1] == 3:  # pair by pair
        found: NDArray[np.bool_] = compiled.segments_hit_boxes(
            np.ascontiguousarray(p0), np.ascontiguousarray(p1),
            np.ascontiguousarray(boxes, dtype=float))
        return found
    # Only boxes whose extent meets the segments' common bounding box can be hit.
    lo = np.minimum(p0.min(axis=0), p1.min(axis=0))
    hi = np.maximum(p0.max(axis=0), p1.max(axis=0))
    near = ((boxes[:, 0, 0] <= hi[0]) & (boxes[:, 1, 0] >= lo[0]) & (boxes[:, 0, 1] <= hi[1])
            & (boxes[:, 1, 1] >= lo[1]) & (boxes[:, 0, 2] <= hi[2]) & (boxes[:, 1, 2] >= lo[2]))
    candidates = boxes[near]
    if len(candidates) == 0:
        return np.zeros(len(p0), dtype=bool)
    d = p1 - p0
    if len(p0) * len(candidates) <= JOINT and (np.abs(d) > 1e-300).all():  # 1 / d finite
        # the three axes at once (a few (M, K, 3) arrays): the same numbers, fewer calls
        inv = (1.0 / d)[:, None, :]
        t_a = (candidates[None, :, 0, :] - p0[:, None, :]) * inv
        t_b = (candidates[None, :, 1, :] - p0[:, None, :]) * inv
        enter = np.minimum(t_a, t_b).max(axis=2)
        leave = np.maximum(t_a, t_b).min(axis=2)
        hit = (enter <= leave) & (leave >= 0.0) & (enter <= 1.0)
        return np.asarray(hit.any(axis=1))
    with np.errstate(divide="ignore", invalid="ignore"):  # once, not once an axis
        enter, leave = _slab(p0[:, 0:1], d[:, 0], candidates[None, :, 0, 0],
                             candidates[None, :, 1, 0])
        for k in (1, 2):  # one axis at a time: (M, K) arrays, not (M, K, 3)
            t_near, t_far = _slab(p0[:, k:k + 1], d[:, k], candidates[None, :, 0, k],
                                  candidates[None, :, 1, k])
            enter, leave = np.maximum(enter, t_near), np.minimum(leave, t_far)
    hit = (enter <= leave) & (leave >= 0.0) & (enter <= 1.0)
    return np.asarray(hit.any(axis=1))


def _slab(origin: FloatArray, d: FloatArray, lo: FloatArray,
          hi: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Where segments (``origin`` ``(M, 1)``, direction ``d`` ``(M,)``) enter and leave the
    slabs ``lo..hi`` (``(1, K)``) of one axis, in units of the segment (under the caller's
    ``np.errstate``: a zero component divides by zero)."""
    inv = (1.0 / d)[:, None]
    t_a = (lo - origin) * inv
    t_b = (hi - origin) * inv
    t_near, t_far = np.minimum(t_a, t_b), np.maximum(t_a, t_b)
    if np.isfinite(inv).all():  # then no product is NaN and no component is zero
        return t_near, t_far
    nan_a, nan_b = np.isnan(t_a), np.isnan(t_b)
    if nan_a.any():
        t_near[nan_a] = -np.inf
    if nan_b.any():
        t_far[nan_b] = np.inf
    # A zero direction component: the segment is inside the slab or never enters it.
    parallel = d == 0.0
    if parallel.any():
        inside = (origin[parallel] >= lo) & (origin[parallel] <= hi)
        t_near[parallel] = np.where(inside, -np.inf, np.inf)
        t_far[parallel] = np.where(inside, np.inf, -np.inf)
    return t_near, t_far


def cross2(a: FloatArray, b: FloatArray) -> FloatArray:
    """The z of ``a x b`` for rows of 2-D vectors: ``np.cross``'s products for them, which
    NumPy 2 deprecates (the same bits)."""
    out: FloatArray = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def polyline_length(points: FloatArray) -> float:
    if len(points) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def resample(points: FloatArray, step: float) -> tuple[FloatArray, FloatArray]:
    """Points every ``step`` metres along a polyline, and their arc lengths."""
    points = np.asarray(points, dtype=float)
    if len(points) < 2:
        return points.copy(), np.zeros(len(points))
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    total = cum[-1]
    s = np.append(np.arange(0.0, total, step), total) if total > 0 else np.zeros(1)
    out = np.column_stack([np.interp(s, cum, points[:, k]) for k in range(points.shape[1])])
    return out, s


def inside_polygon(points: FloatArray, polygon: FloatArray | tuple[tuple[float, float], ...]
                   ) -> NDArray[np.bool_]:
    """``(N,)`` mask: is each of ``points`` (``(N, 2)`` or more columns; xy used) inside the
    closed ``polygon`` (``(M, 2)``)? Even-odd rule, vectorised over points and edges.

    Only the points within the polygon's bounds (widened by :data:`BOUNDS_MARGIN`) are
    tested: beyond them no edge spans a point's row, or every spanning edge crosses on one
    side of it, and those come in pairs, so the rule says outside there anyway (a grid of a
    building's cells against one room's outline, say)."""
    p = np.atleast_2d(np.asarray(points, dtype=float))[:, :2]
    a = np.asarray(polygon, dtype=float)
    if len(p) > BOUNDED and len(a):
        lo, hi = a.min(axis=0) - BOUNDS_MARGIN, a.max(axis=0) + BOUNDS_MARGIN
        near = np.flatnonzero((p[:, 0] >= lo[0]) & (p[:, 0] <= hi[0])
                              & (p[:, 1] >= lo[1]) & (p[:, 1] <= hi[1]))
        out = np.zeros(len(p), dtype=bool)
        if len(near):
            out[near] = _even_odd(p[near], a)
        return out
    return _even_odd(p, a)


BOUNDED = 256  # points: from this many, only those within a polygon's bounds are tested
BOUNDS_MARGIN = 1e-6  # m: far beyond the rounding of an edge's crossing
ROWS = 4  # points a row (an ordinate) on average, from which the rule is taken row by row


def _even_odd(p: FloatArray, a: FloatArray) -> NDArray[np.bool_]:
    """The even-odd rule: an edge spanning a point's row (ordinate) counts where it crosses
    that row to the right of the point. Points that share rows (a grid's) are taken a row at
    a time: each row's crossings are worked out once, in the same arithmetic, and sorted."""
    if len(p) >= BOUNDED:
        ys, row = np.unique(p[:, 1], return_inverse=True)
        if len(ys) * ROWS <= len(p):
            return _by_rows(p[:, 0], ys, row.ravel(), a)
    return np.asarray((np.sum(_crossings(p[:, 1:2], a) > p[:, 0:1], axis=1) % 2) == 1)


def _crossings(y: FloatArray, a: FloatArray) -> FloatArray:
    """``(len(y), M)``: where each edge of the closed polygon ``a`` crosses each row ``y``
    (a column), ``-inf`` for an edge that does not span the row."""
    b = np.roll(a, -1, axis=0)
    spans = (a[:, 1] > y) != (b[:, 1] > y)
    dy = np.where(b[:, 1] == a[:, 1], 1.0, b[:, 1] - a[:, 1])
    cross_x = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / dy
    return np.where(spans, cross_x, -np.inf)


def _by_rows(x: FloatArray, ys: FloatArray, row: NDArray[np.intp], a: FloatArray
             ) -> NDArray[np.bool_]:
    """The rule for points at abscissae ``x`` on rows ``ys[row]``: in each row, the count of
    crossings right of a point is the row's crossings less those at or left of it."""
    crossings = np.sort(_crossings(ys[:, None], a), axis=1)
    order = np.argsort(row, kind="stable")
    starts = np.searchsorted(row[order], np.arange(len(ys) + 1))
    right = np.empty(len(x), dtype=np.intp)
    for r in range(len(ys)):
        mine = order[starts[r]:starts[r + 1]]
        right[mine] = a.shape[0] - np.searchsorted(crossings[r], x[mine], side="right")
    return np.asarray(right % 2 == 1)
