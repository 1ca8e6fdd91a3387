"""Coverage paths over a room's floor: spirals, lawnmower sweeps, a walking loop.

Each returns ``(N, 2)`` points in the plane; the caller sets the height. ``spacing`` is the
distance between passes, chosen from the sensor's footprint.
"""

from __future__ import annotations

import numpy as np

from astralis_des.world.geometry import Box, FloatArray


def spiral(box: Box, spacing: float, inward: bool = True,
           margin: float | None = None) -> FloatArray:
    """Rectangular rings, outermost first, ``spacing`` apart; reversed when outward. The
    outermost ring runs ``spacing / 2`` inside the walls, or ``margin`` when that is nearer."""
    x0, y0, x1, y1 = box.lo[0], box.lo[1], box.hi[0], box.hi[1]
    half = min(x1 - x0, y1 - y0) / 2
    pts: list[tuple[float, float]] = []
    k = min(spacing / 2, half, margin if margin is not None else np.inf)
    while k <= half + 1e-9:
        a, b, c, d = x0 + k, y0 + k, x1 - k, y1 - k
        if c - a < 1e-6 or d - b < 1e-6:  # the ring collapsed to a line: the spiral's centre
            pts += [(a, b), (c, d)]
            break
        pts += [(a, b), (c, b), (c, d), (a, d), (a, min(b + spacing, d))]
        k += spacing
    path = _dedupe(np.array(pts))
    return path if inward else path[::-1].copy()


def lawnmower(box: Box, spacing: float, axis: int, margin: float | None = None) -> FloatArray:
    """Back-and-forth lanes parallel to ``axis`` (0: x, "horizontal"; 1: y, "vertical"),
    evenly spread; lanes end ``spacing / 2`` from the walls, or ``margin`` when nearer, and
    the outer lanes keep within ``margin`` of the side walls too."""
    lo, hi = np.array(box.lo[:2]), np.array(box.hi[:2])
    across = 1 - axis
    width = hi[across] - lo[across]
    n = max(1, int(np.ceil(width / spacing)))
    inset = min(spacing / 2, margin if margin is not None else np.inf)
    if n == 1:
        offsets = np.array([lo[across] + width / 2])
    else:
        side = min(width / (2 * n), inset)
        offsets = np.linspace(lo[across] + side, hi[across] - side, n)
    pts = []
    for i, off in enumerate(offsets):
        ends = (lo[axis] + inset, hi[axis] - inset)
        ends = ends if i % 2 == 0 else ends[::-1]
        for e in ends:
            p = np.empty(2)
            p[axis], p[across] = min(max(e, lo[axis]), hi[axis]), off
            pts.append(p)
    return _dedupe(np.array(pts))


def loop(box: Box, inset: float) -> FloatArray:
    """A closed walk around the room, ``inset`` from its walls."""
    k = min(inset, (box.hi[0] - box.lo[0]) / 2, (box.hi[1] - box.lo[1]) / 2)
    a, b, c, d = box.lo[0] + k, box.lo[1] + k, box.hi[0] - k, box.hi[1] - k
    return _dedupe(np.array([(a, b), (c, b), (c, d), (a, d), (a, b)]))


def start_near(path: FloatArray, box: Box, entry: FloatArray) -> FloatArray:
    """Mirror ``path`` in the room so that it starts as close to ``entry`` as it can."""
    centre = np.array(box.center[:2])
    best, best_d = path, np.inf
    for sx in (1.0, -1.0):
        for sy in (1.0, -1.0):
            candidate = centre + (path - centre) * np.array([sx, sy])
            d = float(np.linalg.norm(candidate[0] - entry[:2]))
            if d < best_d - 1e-9:
                best, best_d = candidate, d
    return best


def _dedupe(points: FloatArray) -> FloatArray:
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.linalg.norm(np.diff(points, axis=0), axis=1) > 1e-9
    return points[keep]
