"""A* on a floor slice: the human operator's planner (walkers step around furniture)."""

from __future__ import annotations

import heapq
import math
import time
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.world.geometry import FloatArray

if TYPE_CHECKING:
    from astralis_des.planning.occupancy import GridMap

STEPS = ((1, 0, 1.0), (-1, 0, 1.0), (0, 1, 1.0), (0, -1, 1.0),
         (1, 1, math.sqrt(2)), (1, -1, math.sqrt(2)), (-1, 1, math.sqrt(2)),
         (-1, -1, math.sqrt(2)))


def plan_grid(grid: GridMap, start: FloatArray, goal: FloatArray, radius: float, *,
              budget: float) -> tuple[FloatArray | None, str]:
    """Cells with clearance >= ``radius`` from ``start`` to ``goal`` (x, y): ``(path, "")`` or
    ``(None, reason)``. Gives up when ``budget`` seconds have passed."""
    if budget <= 0:
        return None, f"the time budget must be positive (got {budget:g} s)"
    t0 = time.perf_counter()
    ends = np.array([start[:2], goal[:2]], dtype=float)
    ok = grid.free(ends, radius)
    if not ok[0]:
        return None, "start in collision"
    if not ok[1]:
        return None, "goal in collision"
    passable = grid.distance >= radius
    (si, sj), (gi, gj) = (tuple(int(v) for v in c) for c in grid.cell_of(ends))
    nx, ny = passable.shape
    cost = {(si, sj): 0.0}
    came: dict[tuple[int, int], tuple[int, int]] = {}
    frontier = [(math.hypot(gi - si, gj - sj), 0.0, (si, sj))]
    expanded = 0
    while frontier:
        _, g, cell = heapq.heappop(frontier)
        if cell == (gi, gj):
            return _smooth(grid, _walk_back(came, cell), passable, start, goal), ""
        if g > cost.get(cell, math.inf):
            continue
        expanded += 1
        if expanded % 512 == 0 and time.perf_counter() - t0 > budget:
            return None, f"no path found within {budget:g} s"
        ci, cj = cell
        for di, dj, step in STEPS:
            ni, nj = ci + di, cj + dj
            if not (0 <= ni < nx and 0 <= nj < ny) or not passable[ni, nj]:
                continue
            if di and dj and not (passable[ci + di, cj] and passable[ci, cj + dj]):
                continue  # no cutting corners between two blocked cells
            new = g + step
            if new < cost.get((ni, nj), math.inf):
                cost[(ni, nj)] = new
                came[(ni, nj)] = cell
                heapq.heappush(frontier, (new + math.hypot(gi - ni, gj - nj), new, (ni, nj)))
    return None, "no path: the goal is walled off"


def _walk_back(came: dict[tuple[int, int], tuple[int, int]],
               cell: tuple[int, int]) -> list[tuple[int, int]]:
    cells = [cell]
    while cells[-1] in came:
        cells.append(came[cells[-1]])
    return cells[::-1]


def _smooth(grid: GridMap, cells: list[tuple[int, int]], passable: np.ndarray,
            start: FloatArray, goal: FloatArray) -> FloatArray:
    """Keep only the turns: drop every cell that a straight, clear line can skip."""
    points = grid.center_of(np.array(cells))
    points[0], points[-1] = start[:2], goal[:2]
    kept = [0]
    i = 0
    while i < len(points) - 1:
        j = len(points) - 1
        while j > i + 1 and not _clear(grid, points[i], points[j], passable):
            j -= 1
        kept.append(j)
        i = j
    return np.asarray(points[kept])


def _clear(grid: GridMap, a: FloatArray, b: FloatArray, passable: np.ndarray) -> bool:
    n = max(2, math.ceil(float(np.linalg.norm(b - a)) / (grid.resolution / 2)) + 1)
    samples = a + (b - a) * np.linspace(0.0, 1.0, n)[:, None]
    cells = grid.cell_of(samples)
    inside = np.all((cells >= 0) & (cells < np.array(passable.shape)), axis=1)
    return bool(inside.all() and passable[cells[:, 0], cells[:, 1]].all())
