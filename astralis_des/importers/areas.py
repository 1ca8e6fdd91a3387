"""Search areas on an imported world's open floor: where the assignment can send the team.

Squares of free floor are chosen greedily and deterministically: the first nearest the middle
of the free floor, each next one nearest the last, never overlapping (``GAP`` apart). Each
area's "door" is the middle of its first side (south, west, north, east) that opens onto free
floor. Ids read like room ids, ``GROUP.LEVEL.SEGMENT.AREA`` (levels numbered from the lowest
floor that has areas), so that a mission searches them segment by segment like the rooms of
a building.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

BoolArray = NDArray[np.bool_]
GROUP = "S"
PER_SEGMENT = 2
GAP = 2.0  # m between areas
MIN_SIZE = 4.0  # m: no area smaller than this
SHRINK = 0.75
SIDES = ("south", "west", "north", "east")


@dataclass(frozen=True)
class Area:
    id: str
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    entry: str


@dataclass(frozen=True)
class Level:
    """A floor an area can stand on: its height and its free cells."""

    z: float
    free: BoolArray  # (nx, ny)


Headroom = Callable[[float, slice, slice], float]


def place_areas(levels: list[Level], cell: float, count: int, size: float,
                headroom: Headroom) -> list[Area]:
    """Up to ``count`` squares of ``size`` m (smaller where none fits, down to ``MIN_SIZE``),
    filling the levels in the order given."""
    placed: list[tuple[int, slice, slice, float]] = []  # level number, cells, floor
    for n in range(len(levels)):
        free = levels[n].free.copy()
        side = max(round(size / cell), 1)
        last: tuple[float, float] | None = None
        while len(placed) < count and side * cell >= MIN_SIZE - 1e-9:
            spot = _best_square(free, side, last)
            if spot is None:
                side = int(side * SHRINK)
                continue
            i, j = spot
            placed.append((n, slice(i, i + side), slice(j, j + side), levels[n].z))
            gap = math.ceil(GAP / cell)
            free[max(i - gap, 0):i + side + gap, max(j - gap, 0):j + side + gap] = False
            last = (i + side / 2, j + side / 2)
        if len(placed) >= count:
            break
    return _name(placed, levels, cell, headroom)


def _best_square(free: BoolArray, side: int, near: tuple[float, float] | None
                 ) -> tuple[int, int] | None:
    """Corner cell of the free ``side`` x ``side`` square nearest ``near`` (or the middle of
    the free cells), ties broken by index."""
    nx, ny = free.shape
    if side > nx or side > ny or not free.any():
        return None
    blocked = np.pad((~free).astype(np.int64), ((1, 0), (1, 0))).cumsum(0).cumsum(1)
    window = blocked[side:, side:] - blocked[:-side, side:] - blocked[side:, :-side] + \
        blocked[:-side, :-side]
    ci, cj = np.nonzero(window == 0)
    if len(ci) == 0:
        return None
    target = near if near is not None else ndimage.center_of_mass(free)
    d = (ci + side / 2 - target[0]) ** 2 + (cj + side / 2 - target[1]) ** 2
    best = int(np.lexsort((cj, ci, d))[0])
    return int(ci[best]), int(cj[best])


def _name(placed: list[tuple[int, slice, slice, float]], levels: list[Level], cell: float,
          headroom: Headroom) -> list[Area]:
    heights = sorted({z for _, _, _, z in placed})  # levels numbered from the lowest used
    areas = []
    counts: dict[int, int] = {}
    for level_index, si, sj, z in placed:
        number = heights.index(z) + 1
        k = counts.get(number, 0)
        counts[number] = k + 1
        seg, nth = k // PER_SEGMENT + 1, k % PER_SEGMENT + 1
        lo = (si.start * cell, sj.start * cell, z)
        hi = (si.stop * cell, sj.stop * cell, z + headroom(z, si, sj))
        entry = _entry(levels[level_index].free, si, sj)
        areas.append(Area(f"{GROUP}.{number}.{seg}.{nth}", _round(lo), _round(hi), entry))
    return areas


def _entry(free: BoolArray, si: slice, sj: slice) -> str:
    """The first side whose middle opens onto a free cell just outside the square."""
    mid_i, mid_j = (si.start + si.stop) // 2, (sj.start + sj.stop) // 2
    outside = {"south": (mid_i, sj.start - 2), "west": (si.start - 2, mid_j),
               "north": (mid_i, sj.stop + 1), "east": (si.stop + 1, mid_j)}
    for side in SIDES:
        i, j = outside[side]
        if 0 <= i < free.shape[0] and 0 <= j < free.shape[1] and free[i, j]:
            return side
    return SIDES[0]


def _round(p: tuple[float, float, float]) -> tuple[float, float, float]:
    return (round(p[0], 3), round(p[1], 3), round(p[2], 3))
