"""A long body's footprint (the Husky's rectangle): the points of its rim at a pose, the
heading it fits at, and whether it fits at a point at any heading (the planner's check)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.world.geometry import FloatArray

if TYPE_CHECKING:
    from astralis_des.planning.occupancy import GridMap

RIM = 0.25  # m between the points a rectangular footprint is checked at, along its edges
TURNS = np.deg2rad(np.array([0, 15, -15, 30, -30, 45, -45, 60, -60, 75, -75, 90, -90, 105, -105,
                             120, -120, 135, -135, 150, -150, 165, -165, 180]))  # tried in turn


def rectangle_points(states: FloatArray, length: float, width: float) -> FloatArray:
    """``(N, K, 2)``: points along the rim of a ``length`` x ``width`` body (and its centre)
    at each ``(x, y, heading)`` state, ``RIM`` apart at most."""
    along = np.linspace(-length / 2, length / 2, max(2, math.ceil(length / RIM) + 1))
    across = np.linspace(-width / 2, width / 2, max(2, math.ceil(width / RIM) + 1))
    rim = np.vstack([np.column_stack([along, np.full_like(along, -width / 2)]),
                     np.column_stack([along, np.full_like(along, width / 2)]),
                     np.column_stack([np.full_like(across, -length / 2), across]),
                     np.column_stack([np.full_like(across, length / 2), across]),
                     [[0.0, 0.0]]])
    cos, sin = np.cos(states[:, 2]), np.sin(states[:, 2])
    x = states[:, None, 0] + cos[:, None] * rim[None, :, 0] - sin[:, None] * rim[None, :, 1]
    y = states[:, None, 1] + sin[:, None] * rim[None, :, 0] + cos[:, None] * rim[None, :, 1]
    return np.stack([x, y], axis=2)


def facing(valid, state: FloatArray) -> FloatArray:  # type: ignore[no-untyped-def]
    """``state`` (x, y, heading), turned to the nearest heading its footprint fits at, if
    it does not fit at its own (a long body by a wall fits along it, not across)."""
    candidates = np.repeat(state[None, :], 2 * len(TURNS), axis=0)
    candidates[:, 2] = np.concatenate([state[2] + TURNS, TURNS])  # then as fits_turned
    ok = valid(candidates)
    return np.asarray(candidates[int(np.argmax(ok))]) if ok.any() else state


def rectangle_free(grid: GridMap, states: FloatArray, footprint: tuple[float, float],
                   clearance: float) -> np.ndarray:
    """``(N,)``: where a body of ``footprint`` (length, width) at each ``(x, y, heading)``
    state is clear by ``clearance`` on ``grid`` (the UGV planner's validity test)."""
    rims = rectangle_points(states, *footprint)
    return np.asarray(grid.free(rims.reshape(-1, 2), clearance).reshape(len(states), -1)
                      .all(axis=1))


def fits_turned(grid: GridMap, points: FloatArray, footprint: tuple[float, float],
                clearance: float) -> np.ndarray:
    """``(N,)``: where a body of ``footprint`` (length, width) fits at some heading of
    ``TURNS`` with ``clearance`` to spare on ``grid``: where its planner can start or stop."""
    pts = np.atleast_2d(points)
    states = np.column_stack([np.repeat(pts[:, :2], len(TURNS), axis=0),
                              np.tile(TURNS, len(pts))])
    ok = rectangle_free(grid, states, footprint, clearance)
    return np.asarray(ok.reshape(len(pts), len(TURNS)).any(axis=1))
