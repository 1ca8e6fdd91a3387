"""Coverage paths over a room's floor: spirals, lawnmower sweeps, a walking loop.

Each returns ``(N, 2)`` points in the plane; the caller sets the height. ``spacing`` is the
distance between passes, chosen from the sensor's footprint.
"""

from __future__ import annotations

import numpy as np

from astralis_des.world.geometry import Box, FloatArray, cross2, inside_polygon

STEP = 0.25  # m: a pattern is cut to a room's outline at points this far apart


def spiral(box: Box, spacing: float, inward: bool = True,
           margin: float | None = None, min_turns: int = 2) -> FloatArray:
    """A rectangular spiral from the walls to the centre (``inward``) or from the centre to the
    walls: each side runs a quarter of a ring's spacing nearer the centre than the one before,
    so the path never crosses itself and its corners come ever nearer the centre (farther,
    outward). Rings are ``spacing`` apart (the camera's footprint), closer when needed to
    make at least ``min_turns`` turns; the first side runs ``spacing / 2`` inside the walls,
    or ``margin`` when that is nearer, and never more than half way to the centre."""
    lo, hi = np.array(box.lo[:2], dtype=float), np.array(box.hi[:2], dtype=float)
    if hi[1] - lo[1] > hi[0] - lo[0]:  # drawn with the long axis along x, so that the last
        flipped = Box((box.lo[1], box.lo[0], box.lo[2]), (box.hi[1], box.hi[0], box.hi[2]))
        path = spiral(flipped, spacing, inward, margin, min_turns)  # leg runs along it
        return path[:, ::-1].copy()
    half = float(min(hi - lo)) / 2
    k0 = min(spacing / 2, half / 2, margin if margin is not None else np.inf)
    turns = max(min_turns, int(np.ceil((half - k0) / spacing - 1e-9)))
    step = (half - k0) / turns  # inset gained per turn; a quarter of it per side
    # Sides in turn: south (east-going), east, north, west; each runs a quarter step nearer
    # the centre than the one before, and a corner is where two consecutive sides meet.
    (x0, y0), (x1, y1) = lo, hi
    pts = [(x0 + k0, y0 + k0)]
    for i in range(4 * turns):
        inset = k0 + step * (i + 1) / 4  # of the side that follows: where this one ends
        x, y = pts[-1]
        x, y = ((x1 - inset, y), (x, y1 - inset), (x0 + inset, y), (x, y0 + inset))[i % 4]
        pts.append((x, y))
    pts.append(tuple((lo + hi) / 2))  # the centre: the last leg runs along the long axis
    path = _dedupe(np.array(pts))
    return path if inward else path[::-1].copy()


def lawnmower(box: Box, spacing: float, axis: int, margin: float | None = None,
              min_lanes: int = 2) -> FloatArray:
    """Back-and-forth (boustrophedon) lanes parallel to ``axis`` (0: x, "horizontal"; 1: y,
    "vertical"), evenly spread, as many as ``spacing`` needs across the room (at least
    ``min_lanes``); lanes end ``spacing / 2`` from the walls, or ``margin`` when nearer, and
    the outer lanes keep within ``margin`` of the side walls too."""
    lo, hi = np.array(box.lo[:2]), np.array(box.hi[:2])
    across = 1 - axis
    width = hi[across] - lo[across]
    n = max(min_lanes, int(np.ceil(width / spacing)))
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


def within(path: FloatArray, outline: tuple[tuple[float, float], ...], margin: float
           ) -> FloatArray:
    """The part of ``path`` (drawn over a room's bounds) over the room's ``outline``, at least
    ``margin`` from its edges across each axis: the path cut at points ``STEP`` apart, those
    outside left out, and the corners and the ends of what is left kept. A room that is a
    rectangle (no outline), or one that leaves less than a step of the path, keeps the path
    as it is."""
    if not outline or len(path) < 2:
        return path
    legs = np.diff(path, axis=0)
    counts = np.maximum(np.ceil(np.linalg.norm(legs, axis=1) / STEP).astype(int), 1)
    dense = np.vstack([path[k] + legs[k] * (np.arange(n) / n)[:, None]
                       for k, n in enumerate(counts)] + [path[-1:]])
    reach = margin * 0.98  # a pattern inset by ``margin`` from a side lies on it, not outside
    probes = dense[:, None, :] + np.array([[0, 0], [reach, 0], [-reach, 0], [0, reach],
                                           [0, -reach]])
    inside = inside_polygon(probes.reshape(-1, 2), np.asarray(outline)).reshape(-1, 5)
    kept = dense[inside.all(axis=1)]
    if len(kept) < 3 or np.ptp(kept, axis=0).max() < STEP:
        return path  # too little of it over the room: the pattern as it was
    turn = np.abs(cross2(kept[1:-1] - kept[:-2], kept[2:] - kept[1:-1])) > 1e-9
    jump = np.linalg.norm(np.diff(kept, axis=0), axis=1) > STEP * 1.01
    keep = np.ones(len(kept), dtype=bool)
    keep[1:-1] = turn | jump[:-1] | jump[1:]
    return kept[keep]


def _dedupe(points: FloatArray) -> FloatArray:
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.linalg.norm(np.diff(points, axis=0), axis=1) > 1e-9
    return points[keep]
