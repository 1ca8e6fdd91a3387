"""What is taken on a room's grid while it is furnished, and whether a footprint cuts floor off.

A footprint is kept when every free cell a robot as wide as the passage reached from the door
before is still reached (or lies under the footprint, grown by half the passage). Labelling the
grid's regions again answers that; most footprints are settled without, by the ring of cells
round what they take (:func:`_keeps_reach`), with the same answer and the same cells reached.
A footprint given up is undone from what its stamp overwrote, not from copies of every grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from astralis_des.memo import kept
from astralis_des.world.freespace import BoolArray, FreeSpace, IntArray
from astralis_des.world.geometry import Box
from astralis_des.world.grids import (
    Cells,
    disk,
    disk_grown,
    erode,
    erode_near,
    near,
    padded,
    reachable,
    summed,
    walkable,
    window,
)

SHIFTED = 4  # clearances (cells) up to which the cells near a taken one are found by shifts
# what a stamp overwrote, to undo it: (array, cells, their values before)
Undo = list[tuple[BoolArray, Cells, BoolArray]]


@dataclass
class Occupancy:
    """What is already taken on a room's grid, and what is reachable around it."""

    taken: BoolArray  # cells under a footprint
    halo: BoolArray  # cells under a footprint grown by its clearance
    keepout: BoolArray  # cells kept empty (in front of the door)
    reach: BoolArray  # free cells a robot's centre can reach from the door
    walk_eroded: BoolArray  # where the centre of a robot as wide as the passage fits
    # by a clearance in cells: the cells within it of a taken one, kept up to date as
    # footprints are stamped (what a footprint's window must not hold)
    near: dict[int, BoolArray] = field(default_factory=dict)

    @classmethod
    def empty(cls, space: FreeSpace, keepout: BoolArray, passage: float) -> Occupancy:
        """Nothing placed yet; the empty room's reachability is worked out once per room
        and passage (its arrays are replaced, never changed, as footprints are placed)."""
        taken = np.zeros(space.shape, dtype=bool)
        reach: dict[float, tuple[BoolArray, BoolArray]] = kept(space, "empty_reach", 64)
        if passage not in reach:
            reach[passage] = _reach(space, taken, passage)
            for array in reach[passage]:
                array.setflags(write=False)
        return cls(taken, taken.copy(), keepout, *reach[passage])

    def settle(self, space: FreeSpace, passage: float) -> None:
        """Reachability again after footprints were stamped by hand."""
        self.reach, self.walk_eroded = _reach(space, self.taken, passage)

    def near_taken(self, grow: int) -> BoolArray:
        """Cells within ``grow`` cells (a square) of a taken one."""
        if grow not in self.near:
            if grow <= SHIFTED:
                self.near[grow] = near(self.taken, grow)
            else:
                table = summed(padded(self.taken, grow, False))
                self.near[grow] = window(table, 2 * grow + 1, 2 * grow + 1) > 0
        return self.near[grow]

    def stamp(self, space: FreeSpace, box: Box, clearance: float) -> Undo:
        """Take the cells under ``box`` (and its halo, grown by ``clearance``); returns what
        it overwrote, the taken cells' first (:meth:`undo` puts it back)."""
        undo: Undo = []
        rows, cols = space.cells(box.lo, box.hi)
        _set(undo, self.taken, (rows, cols))
        (i0, i1), (j0, j1) = (rows.start, rows.stop), (cols.start, cols.stop)
        if i0 < i1 and j0 < j1:  # taken is the union of the stamped rectangles
            for g, near in self.near.items():
                _set(undo, near, (slice(max(i0 - g, 0), i1 + g), slice(max(j0 - g, 0), j1 + g)))
        grow = (clearance, clearance, 0.0)
        lo = tuple(a - g for a, g in zip(box.lo, grow, strict=True))
        hi = tuple(a + g for a, g in zip(box.hi, grow, strict=True))
        _set(undo, self.halo, space.cells(lo, hi))
        return undo

    @staticmethod
    def undo(undo: Undo) -> None:
        """Put back what a :meth:`stamp` overwrote (a footprint tried and given up)."""
        for array, cells, before in reversed(undo):
            array[cells] = before

    def try_stamp(self, space: FreeSpace, box: Box, clearance: float, passage: float) -> bool:
        """Stamp ``box`` if every cell reached from the door before is still reached (or
        lies under it, grown by half the ``passage``), and say whether it was kept."""
        undo = self.stamp(space, box, clearance)
        stamped, taken_before = undo[0][1], undo[0][2]
        radius = passage / 2 / space.cell
        # the walk lost the whole rectangle (the usual case): all of it was free floor (which
        # lies inside the room) and none of it was taken
        if space.free[stamped].all() and not taken_before.any():
            cleared = disk_grown(radius, stamped)  # what erode_without clears, once for both
            walk_eroded = self.walk_eroded.copy()
            for cells in cleared:
                walk_eroded[cells] = False
            if _keeps_reach(space, self.reach, radius, stamped):
                self.reach = self.reach.copy()
                for cells in cleared:
                    self.reach[cells] = False
                self.walk_eroded = walk_eroded
                return True
        else:
            walk_eroded = erode_near(walkable(space, self.taken), radius, stamped,
                                     self.walk_eroded)
        eroded, reach = reachable(space, self.taken, passage, walk_eroded)
        if (eroded & self.reach & ~reach).any():
            self.undo(undo)
            return False
        self.reach, self.walk_eroded = reach, walk_eroded
        return True

    def kept_compiled(self, reach: BoolArray, walk_eroded: BoolArray) -> None:
        """A footprint the compiled kernels stamped and kept (``compiled.loops.place``, as
        :meth:`try_stamp` would have): what it reaches and erodes now."""
        self.reach, self.walk_eroded = reach, walk_eroded
        self.near.clear()  # made again from ``taken`` when asked (the kernels do not keep it)


@lru_cache(maxsize=256)
def disk_rows(radius: float) -> IntArray:
    """:func:`grids.disk_grown`'s disk as an array (rows off its centre, half widths)."""
    return np.array(disk(radius), dtype=np.int64).reshape(-1, 2)


def _set(undo: Undo, array: BoolArray, cells: Cells) -> None:
    undo.append((array, cells, array[cells].copy()))
    array[cells] = True


@dataclass(frozen=True)
class _Ring:
    """The cells round a rectangle grown as :func:`erode_without` grows it, which touch it
    (by a side or a corner): a closed path, each cell joined to the next by a side."""

    rows: IntArray  # offsets from the rectangle's first cell
    cols: IntArray
    flat: IntArray  # the same on the room's grid, raveled
    ends: tuple[IntArray, IntArray]  # the path's steps: pairs of indices into rows, cols
    grow: int  # cells the rectangle grows by, at most


def _ring(space: FreeSpace, kx: int, ky: int, radius: float) -> _Ring | None:
    """The ring round a ``kx`` by ``ky`` rectangle grown by ``radius`` cells on the room's
    grid, or None where its cells make no simple closed path."""
    return _make_ring(kx, ky, radius, space.shape[1])


@lru_cache(maxsize=4096)
def _make_ring(kx: int, ky: int, radius: float, width: int) -> _Ring | None:
    grow = math.floor(radius + 1e-9)
    o = grow + 2
    grown = np.zeros((kx + 2 * o, ky + 2 * o), dtype=bool)
    for di in range(grow + 1):  # as erode_without clears them
        h = math.floor(math.sqrt(radius * radius - di * di) + 1e-9)
        grown[o - di:o + kx + di, o - h:o + ky + h] = True
    near = grown.copy()  # grown by a cell each way, corners too (a 3 x 3 dilation)
    near[1:] |= grown[:-1]
    near[:-1] |= grown[1:]
    wide = near.copy()
    wide[:, 1:] |= near[:, :-1]
    wide[:, :-1] |= near[:, 1:]
    ring = wide & ~grown
    index = np.full(ring.shape, -1)
    rows, cols = np.nonzero(ring)
    index[rows, cols] = np.arange(len(rows))
    down, across = ring[:-1, :] & ring[1:, :], ring[:, :-1] & ring[:, 1:]
    first = np.concatenate([index[:-1, :][down], index[:, :-1][across]])
    second = np.concatenate([index[1:, :][down], index[:, 1:][across]])
    if not _one_loop(first.tolist(), second.tolist(), len(rows)):
        return None
    rows, cols = rows - o, cols - o
    return _Ring(rows, cols, rows * width + cols, (first, second), grow)


def _one_loop(first: list[int], second: list[int], cells: int) -> bool:
    """Whether the steps join the cells into a single closed path (each cell in two steps,
    and a walk along them from a cell meets every cell before it is back)."""
    joined: list[list[int]] = [[] for _ in range(cells)]
    for a, b in zip(first, second, strict=True):
        joined[a].append(b)
        joined[b].append(a)
    if cells < 4 or any(len(j) != 2 for j in joined):
        return False
    before, here, walked = 0, joined[0][0], 1
    while here != 0:
        before, here = here, joined[here][0] if joined[here][0] != before else joined[here][1]
        walked += 1
    return walked == cells


def _keeps_reach(space: FreeSpace, reach: BoolArray, radius: float, lost: Cells) -> bool:
    """Whether every cell ``reach``ed from the door stays reached but those :func:`erode_without`
    clears round the rectangle ``lost`` (the walk lost it, so these are all the eroded floor
    loses). Sure when no door cell lies there and the reached cells of the ring round them
    make one stretch of it (or the whole ring): a way from a reached cell to the door through
    the cleared ones enters and leaves them beside the ring, and goes round along it instead.
    False: not sure (label the grid again)."""
    (i0, i1), (j0, j1) = (lost[0].start, lost[0].stop), (lost[1].start, lost[1].stop)
    if i0 >= i1 or j0 >= j1:
        return False
    ring = _ring(space, i1 - i0, j1 - j0, radius)
    if ring is None:
        return False
    door = _door_bounds(space)
    g = ring.grow
    if door is not None and i0 - g <= door[1] and door[0] < i1 + g and j0 - g <= door[3] \
            and door[2] < j1 + g:
        return False
    nx, ny = reach.shape
    if i0 - g > 0 and i1 + g < nx and j0 - g > 0 and j1 + g < ny:  # the ring on the grid
        held = reach.ravel()[ring.flat + (i0 * ny + j0)]
    else:
        rows, cols = ring.rows + i0, ring.cols + j0
        on_grid = (rows >= 0) & (rows < nx) & (cols >= 0) & (cols < ny)
        held = reach[np.minimum(np.maximum(rows, 0), nx - 1),
                     np.minimum(np.maximum(cols, 0), ny - 1)] & on_grid
    joined = int(np.count_nonzero(held[ring.ends[0]] & held[ring.ends[1]]))
    return int(np.count_nonzero(held)) - joined <= 1  # stretches of a closed path: cells - steps


def _door_bounds(space: FreeSpace) -> tuple[int, int, int, int] | None:
    """The first and last rows and columns of the room's door cells (None: it has none)."""
    reach: dict[object, object] = kept(space, "empty_reach", 64)
    if "door" not in reach:
        rows, cols = np.nonzero(space.door)
        reach["door"] = None if len(rows) == 0 else (int(rows.min()), int(rows.max()),
                                                     int(cols.min()), int(cols.max()))
    found: tuple[int, int, int, int] | None = reach["door"]  # type: ignore[assignment]
    return found


def _reach(space: FreeSpace, taken: BoolArray, passage: float) -> tuple[BoolArray, BoolArray]:
    """The cells reachable from the door, and the walkable floor eroded by half the passage
    (what placing the next footprint updates around it)."""
    walk_eroded = erode(walkable(space, taken), passage / 2 / space.cell)
    return reachable(space, taken, passage, walk_eroded)[1], walk_eroded
