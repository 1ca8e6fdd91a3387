"""Summed-area tables, erosion and reachability on a room's floor grid (for furnishing).

Placing one footprint changes the floor only under it, so the erosion of the walkable floor
is updated in a window around the footprint (:func:`erode_near`), identical to eroding the
whole grid again.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np
from scipy import ndimage

from astralis_des.memo import kept
from astralis_des.world.freespace import CROSS, BoolArray, FreeSpace

Cells = tuple[slice, slice]


def summed(mask: BoolArray) -> np.ndarray:
    """Summed-area table of ``mask``, one row and column of zeros in front."""
    table = np.zeros((mask.shape[0] + 1, mask.shape[1] + 1), dtype=np.int32)
    table[1:, 1:] = mask  # accumulating int32 in place: twice as fast as cumsum from bool
    np.add.accumulate(table, axis=0, out=table)
    np.add.accumulate(table, axis=1, out=table)
    return table


def window(table: np.ndarray, kx: int, ky: int) -> np.ndarray:
    """``[i, j]``: how many cells of ``mask[i:i + kx, j:j + ky]`` are set (from its table)."""
    nx, ny = table.shape[0] - 1, table.shape[1] - 1
    if kx > nx or ky > ny:
        return np.zeros((0, 0), dtype=np.int32)
    out: np.ndarray = table[kx:, ky:] - table[:-kx, ky:]  # in place from here: no temporaries
    out -= table[kx:, :-ky]
    out += table[:-kx, :-ky]
    return out


def near(mask: BoolArray, grow: int) -> BoolArray:
    """Cells within ``grow`` cells of a set one (a square): the window of ``2 * grow + 1`` cells
    round each holds one, grown one axis at a time by shifted copies (a few calls for the
    small squares of clearances, where a summed-area table costs more)."""
    out = mask.copy()
    for step in range(1, grow + 1):
        out[step:] |= mask[:-step]
        out[:-step] |= mask[step:]
    rows = out.copy()
    for step in range(1, grow + 1):
        out[:, step:] |= rows[:, :-step]
        out[:, :-step] |= rows[:, step:]
    return out


def padded(mask: BoolArray, width: int, value: bool) -> BoolArray:
    """``np.pad(mask, width, constant_values=value)``, without its overhead (small grids)."""
    nx, ny = mask.shape
    out = np.full((nx + 2 * width, ny + 2 * width), value, dtype=bool)
    out[width:width + nx, width:width + ny] = mask
    return out


def erode(walk: BoolArray, radius: float) -> BoolArray:
    """Cells whose disk of ``radius`` cells is all ``walk`` (beyond the grid is not).

    The disk is a union of centred rectangles, one per row offset, each tested in O(1) per cell
    with a summed-area table: a few times faster than a general morphological erosion.
    """
    reach = math.floor(radius + 1e-9)
    nx, ny = walk.shape
    table = summed(padded(~walk, reach, True))
    inner = np.ones(walk.shape, dtype=bool)
    for di in range(reach + 1):
        h = math.floor(math.sqrt(radius * radius - di * di) + 1e-9)
        counts = window(table, 2 * di + 1, 2 * h + 1)
        inner &= counts[reach - di:reach - di + nx, reach - h:reach - h + ny] == 0
    return inner


def walkable(space: FreeSpace, taken: BoolArray) -> BoolArray:
    """Where a robot may stand: free floor not taken, and the open floor outside the room."""
    out: BoolArray = (space.free & ~taken) | (space.open_floor & ~space.inside)
    return out


def erode_near(walk: BoolArray, radius: float, changed: Cells, before: BoolArray) -> BoolArray:
    """:func:`erode` of ``walk`` when it differs from the walk eroded to ``before`` only in
    the cells ``changed``: only cells whose disk meets them can change, and their disks read
    ``walk`` only within ``radius`` of them."""
    reach = math.floor(radius + 1e-9)
    out = before.copy()
    inner, outer = [], []
    for k, part in enumerate(changed):
        n = walk.shape[k]
        lo, hi = max(part.start - reach, 0), min(part.stop + reach, n)
        if lo >= hi:
            return out
        inner.append((lo, hi))
        outer.append((max(lo - reach, 0), min(hi + reach, n)))
    local = erode(walk[outer[0][0]:outer[0][1], outer[1][0]:outer[1][1]], radius)
    (a0, a1), (b0, b1) = inner
    out[a0:a1, b0:b1] = local[a0 - outer[0][0]:a1 - outer[0][0], b0 - outer[1][0]:b1 - outer[1][0]]
    return out


def erode_without(before: BoolArray, radius: float, lost: Cells) -> BoolArray:
    """:func:`erode` of a walk that lost the rectangle of cells ``lost`` (all of them walk
    before) from the walk eroded to ``before``: a cell stays when its disk misses the
    rectangle, i.e. ``before`` less the rectangle grown by the disk (a union of rectangles,
    as in :func:`erode`)."""
    out = before.copy()
    for cells in disk_grown(radius, lost):
        out[cells] = False
    return out


def disk_grown(radius: float, lost: Cells) -> list[Cells]:
    """The rectangle ``lost`` grown by a disk of ``radius`` cells, as the union of rectangles
    :func:`erode_without` clears (none for an empty one)."""
    (i0, i1), (j0, j1) = (lost[0].start, lost[0].stop), (lost[1].start, lost[1].stop)
    if i0 >= i1 or j0 >= j1:
        return []
    return [(slice(max(i0 - di, 0), i1 + di), slice(max(j0 - h, 0), j1 + h))
            for di, h in disk(radius)]


@lru_cache(maxsize=256)
def disk(radius: float) -> tuple[tuple[int, int], ...]:
    """A disk of ``radius`` cells as rows ``di`` off its centre and their half widths ``h``."""
    reach = math.floor(radius + 1e-9)
    return tuple((di, math.floor(math.sqrt(radius * radius - di * di) + 1e-9))
                 for di in range(reach + 1))


def reachable(space: FreeSpace, taken: BoolArray, passage: float,
              walk_eroded: BoolArray | None = None) -> tuple[BoolArray, BoolArray]:
    """Free cells a robot ``passage`` wide can stand on, and those it reaches from the door;
    ``walk_eroded``: the walkable floor already eroded by half the passage, when known."""
    if walk_eroded is None:
        walk_eroded = erode(walkable(space, taken), passage / 2 / space.cell)
    eroded = walk_eroded & space.free & ~taken
    labels, count = ndimage.label(eroded, CROSS)
    from_door = np.zeros(count + 1, dtype=bool)
    from_door[labels[space.door & eroded]] = True
    from_door[0] = False
    return eroded, from_door[labels]


def wall_sides(space: FreeSpace) -> BoolArray:
    """The room's :meth:`FreeSpace.wall_sides` (read-only: kept on its free space)."""
    kept_backs: dict[object, Any] = kept(space, "wall_backs", 4096)
    if "wall sides" not in kept_backs:
        sides = space.wall_sides()
        sides.setflags(write=False)
        kept_backs["wall sides"] = sides
    found: BoolArray = kept_backs["wall sides"]
    return found


def backs_onto_wall(space: FreeSpace, wall: int, kx: int, ky: int) -> BoolArray:
    """Corners whose ``kx`` by ``ky`` window's back row or column lies wholly along the wall
    on side ``wall`` (the room's own: kept on its free space, by wall and window)."""
    kept_backs: dict[object, Any] = kept(space, "wall_backs", 4096)
    key = (wall, kx, ky)
    if key not in kept_backs:
        if "sides" not in kept_backs:  # the summed-area tables of the four walls' cells
            kept_backs["sides"] = [summed(side) for side in space.wall_sides()]
        side = kept_backs["sides"][wall]
        nx, ny = space.shape[0] - kx + 1, space.shape[1] - ky + 1
        if wall in (0, 1):
            start = 0 if wall == 0 else kx - 1
            backs = window(side, 1, ky)[start:start + nx, :ny] == ky
        else:
            start = 0 if wall == 2 else ky - 1
            backs = window(side, kx, 1)[:nx, start:start + ny] == kx
        backs.setflags(write=False)
        kept_backs[key] = backs
    out: BoolArray = kept_backs[key]
    return out


def wall_windows(space: FreeSpace, wall: int, kx: int,
                 ky: int) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
    """The corners :func:`backs_onto_wall` allows (flat indices into its grid, in order), and
    where a summed-area table of the room's grid (raveled) holds the four corners of each one's
    ``kx`` by ``ky`` window, in :func:`window`'s order: so that the windows along the wall are
    counted alone, not every window of the grid (kept on the room's free space, as the backs)."""
    kept_backs: dict[object, Any] = kept(space, "wall_backs", 4096)
    key = ("windows", wall, kx, ky)
    if key not in kept_backs:
        rows, cols = np.nonzero(backs_onto_wall(space, wall, kx, ky))
        width = space.shape[1] + 1  # the table's
        base = rows * width + cols
        corners = rows * (space.shape[1] - ky + 1) + cols
        kept_backs[key] = (corners, (base + kx * width + ky, base + ky, base + kx * width, base))
    found: tuple[np.ndarray, tuple[np.ndarray, ...]] = kept_backs[key]
    return found
