"""Which way a building's walls run: the heading that lines them up with the plan's axes.

Most buildings are rectilinear, and their plans come out best on a grid along their walls: a
door's width is then a run of cells, a wall's outline closes flush (:mod:`.plan`). Seen along
the walls, the points of a wall fall in one narrow band, so the histograms of the points' two
coordinates are most peaked (their sums of squared counts largest) when the axes run along the
walls. The heading is searched over a quarter turn (walls at right angles repeat each quarter),
every ``COARSE`` degrees, then every ``FINE`` degrees round the best.
"""

from __future__ import annotations

import math

import numpy as np

from astralis_des.world.geometry import FloatArray

BIN = 0.02  # m, the histograms' bins
COARSE, FINE = 1.0, 0.05  # degrees
SAMPLE = 200_000  # points looked at, evenly spaced in the cloud


def wall_heading(xy: FloatArray) -> float:
    """The angle (radians, in [-pi/4, pi/4)) of the walls through the ``(N, 2)`` points to the
    x axis; 0 for fewer than two points."""
    if len(xy) < 2:
        return 0.0
    sample = np.asarray(xy[:: max(1, len(xy) // SAMPLE)], dtype=float)
    sample = sample - sample.mean(axis=0)
    coarse = np.arange(-45.0, 45.0, COARSE)
    best = max(coarse, key=lambda a: _peakiness(sample, a))
    fine = np.arange(best - COARSE, best + COARSE + FINE / 2, FINE)
    angle = float(max(fine, key=lambda a: _peakiness(sample, a)))
    angle = round(angle / FINE) * FINE
    return math.radians((angle + 45.0) % 90.0 - 45.0)


def _peakiness(xy: FloatArray, degrees: float) -> float:
    """How peaked the histograms of ``xy`` turned by ``-degrees`` are."""
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    total = 0.0
    for along in (xy[:, 0] * c + xy[:, 1] * s, -xy[:, 0] * s + xy[:, 1] * c):
        counts = np.bincount(np.floor((along - along.min()) / BIN).astype(np.int64))
        total += float(np.dot(counts, counts))
    return total


def turned(xy: FloatArray, angle: float) -> FloatArray:
    """``(N, 2+)`` points turned by ``angle`` (radians) about the origin, anticlockwise; any
    further columns (heights) kept."""
    if angle == 0.0:
        return np.asarray(xy)
    c, s = math.cos(angle), math.sin(angle)
    out = np.array(xy, dtype=float)
    out[:, 0] = xy[:, 0] * c - xy[:, 1] * s
    out[:, 1] = xy[:, 0] * s + xy[:, 1] * c
    return out
