"""What is taken on a room's grid while it is furnished, and whether a footprint cuts floor off.

A footprint is kept when every free cell a robot as wide as the passage reached from the door
before is still reached (or lies under the footprint, grown by half the passage). A footprint
given up is undone from what its stamp overwrote (a few small windows), not from copies of
every grid.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from astralis_des.memo import kept
from astralis_des.world.freespace import BoolArray, FreeSpace
from astralis_des.world.geometry import Box
from astralis_des.world.grids import (
    Cells,
    erode,
    erode_near,
    erode_without,
    padded,
    reachable,
    summed,
    walkable,
    window,
)

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
        was = space.free[stamped] & ~taken_before
        outside = space.open_floor[stamped] & ~space.inside[stamped]
        if (was & ~outside).all():  # the walk lost the whole rectangle (the usual case)
            walk_eroded = erode_without(self.walk_eroded, radius, stamped)
        else:
            walk_eroded = erode_near(walkable(space, self.taken), radius, stamped,
                                     self.walk_eroded)
        eroded, reach = reachable(space, self.taken, passage, walk_eroded)
        if (eroded & self.reach & ~reach).any():
            self.undo(undo)
            return False
        self.reach, self.walk_eroded = reach, walk_eroded
        return True


def _set(undo: Undo, array: BoolArray, cells: Cells) -> None:
    undo.append((array, cells, array[cells].copy()))
    array[cells] = True


def _reach(space: FreeSpace, taken: BoolArray, passage: float) -> tuple[BoolArray, BoolArray]:
    """The cells reachable from the door, and the walkable floor eroded by half the passage
    (what placing the next footprint updates around it)."""
    walk_eroded = erode(walkable(space, taken), passage / 2 / space.cell)
    return reachable(space, taken, passage, walk_eroded)[1], walk_eroded
