"""Doors: where two rooms of a storey meet, and where a room meets the outside (entrances).

Two rooms meet along the line where their watersheds met: cells of one beside cells of the
other, in the middle of the doorway. Each stretch of such a line (cells connected, diagonals
too) is a door; a room with two doors onto the corridor meets it in two stretches. An entrance
is a stretch of a room's cells beside the outside (the cells the building's outline leaves
out). In both, the cells face each other across the door mostly along one axis, the door's
``normal_axis``. Along the other axis, through the stretch's middle, the run of cells clear of
walls between the door's jambs gives its width and centre (the stretch's own length and middle
when the run is much longer: rooms meeting away from any wall). A door narrower than
``MIN_DOOR`` is a slit left by missing points, no door.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from astralis_des.importers.indoor.plan import Plan
from astralis_des.importers.indoor.rooms import MIN_DOOR, IntArray
from astralis_des.world.geometry import FloatArray

OUTSIDE = -1  # the label of the outside, in a door's sides
SLACK = 0.5  # m, how much wider than where two rooms touch the gap between jambs may be


@dataclass(frozen=True)
class FoundDoor:
    """A door of a storey: ``rooms`` are the ids of the rooms on its low and its high side
    along ``normal_axis`` (0: the door's wall is the line x = const, as in
    :class:`astralis_des.world.parts.Door`); ``None`` is the outside (an entrance)."""

    storey: int
    centre: tuple[float, float]
    width: float
    normal_axis: int
    rooms: tuple[str | None, str | None]

    @property
    def entrance(self) -> bool:
        return None in self.rooms


@dataclass
class _Stretch:
    """Side-by-side cells of two labels: per axis, the low cells and how many pairs."""

    cells: list[IntArray]  # (K, 2) arrays of the cells on both sides
    low: dict[int, list[int]]  # axis -> the label on the low side of each pair


def find_doors(plan: Plan, labels: IntArray, ids: dict[int, str]) -> list[FoundDoor]:
    """The doors between rooms and the entrances of a storey's ``labels`` (``ids``: each
    label's room id)."""
    outside = np.where(plan.inside, 0, OUTSIDE)
    grid = np.where(labels > 0, labels, outside)
    pairs: dict[tuple[int, int], _Stretch] = defaultdict(lambda: _Stretch([], {0: [], 1: []}))
    for axis in (0, 1):
        a = grid[:-1, :] if axis == 0 else grid[:, :-1]
        b = grid[1:, :] if axis == 0 else grid[:, 1:]
        touch = (a != b) & (np.maximum(a, b) > 0) & (np.minimum(a, b) != 0)
        i, j = np.nonzero(touch)
        step = np.array([1, 0] if axis == 0 else [0, 1])
        first = np.column_stack([i, j])
        la, lb = a[touch], b[touch]
        for key in set(zip(np.minimum(la, lb).tolist(), np.maximum(la, lb).tolist(),
                           strict=True)):
            mine = (np.minimum(la, lb) == key[0]) & (np.maximum(la, lb) == key[1])
            stretch = pairs[key]
            stretch.cells += [first[mine], first[mine] + step]
            stretch.low[axis] += la[mine].tolist()
    doors = []
    for (p, q), stretch in sorted(pairs.items()):
        doors += _doors(plan, grid, p, q, stretch, ids)
    return doors


def _doors(plan: Plan, grid: IntArray, p: int, q: int, stretch: _Stretch,
           ids: dict[int, str]) -> list[FoundDoor]:
    cells = np.concatenate(stretch.cells)
    lo = cells.min(axis=0)
    crop = np.zeros(tuple(cells.max(axis=0) - lo + 1), dtype=bool)
    crop[cells[:, 0] - lo[0], cells[:, 1] - lo[1]] = True
    parts, count = ndimage.label(crop, structure=np.ones((3, 3), bool))
    part_of = parts[cells[:, 0] - lo[0], cells[:, 1] - lo[1]]
    # each pair of cells put two cells in ``cells``: the pairs of axis 0 first, then axis 1
    n0 = 2 * len(stretch.low[0])
    pair_part = {0: part_of[:n0].reshape(2, -1)[0] if n0 else part_of[:0],
                 1: part_of[n0:].reshape(2, -1)[0] if len(stretch.low[1]) else part_of[:0]}
    out = []
    for part in range(1, count + 1):
        along = {axis: np.asarray(stretch.low[axis])[pair_part[axis] == part]
                 for axis in (0, 1)}
        normal = 0 if len(along[0]) >= len(along[1]) else 1
        mine = cells[part_of == part]
        if p == OUTSIDE:  # an entrance: on the room's side of the outline's edge
            mine = mine[grid[mine[:, 0], mine[:, 1]] > 0]
        centre = plan.centres(mine).mean(axis=0)
        extent = (int(np.ptp(mine[:, 1 - normal])) + 1) * plan.cell
        gap = _gap(plan, centre, 1 - normal, extent)
        if gap is not None:
            centre[1 - normal], width = gap
        else:
            width = extent
        if width < MIN_DOOR:
            continue
        low = p if np.count_nonzero(along[normal] == p) * 2 >= len(along[normal]) else q
        high = q if low == p else p
        out.append(FoundDoor(plan.storey.index, (round(float(centre[0]), 3),
                                                 round(float(centre[1]), 3)),
                             round(width, 3), normal, (ids.get(low), ids.get(high))))
    return out


def _gap(plan: Plan, centre: FloatArray, along: int, extent: float
         ) -> tuple[float, float] | None:
    """The middle and width of the run of cells inside and clear of walls through ``centre``
    along axis ``along`` (between the door's jambs), or None when that run is more than
    ``SLACK`` longer than ``extent`` (then the rooms meet away from any wall). A jamb's cell
    reaches on average half a cell into the gap: the width counts one cell more than the
    run."""
    i, j = (int(v) for v in plan.cells(centre[None, :])[0])
    cut = (slice(None), j) if along == 0 else (i, slice(None))
    line = plan.walls[cut] | ~plan.inside[cut]
    k = i if along == 0 else j
    if line[k]:
        return None
    walls = np.flatnonzero(line)
    below, above = walls[walls < k], walls[walls > k]
    if not len(below) or not len(above):
        return None
    first, last = int(below[-1]) + 1, int(above[0]) - 1
    width = (last - first + 2) * plan.cell
    if width > extent + SLACK:
        return None
    middle = plan.origin[along] + (first + last + 1) / 2 * plan.cell
    return middle, width
