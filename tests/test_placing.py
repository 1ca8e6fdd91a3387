"""Furnishing's occupancy: a footprint is kept or given up as labelling the whole grid says."""

from __future__ import annotations

import numpy as np

from astralis_des.world import placing
from astralis_des.world.catalogue import default_catalogue
from astralis_des.world.clutter import door_keepout
from astralis_des.world.freespace import FreeSpace, room_free_space
from astralis_des.world.geometry import Box
from astralis_des.world.grids import erode_near, reachable, walkable
from astralis_des.world.model import World
from astralis_des.world.placing import Occupancy

PASSAGE = 0.7


def labelled(space: FreeSpace, occupancy: Occupancy,
             box: Box) -> tuple[bool, np.ndarray, np.ndarray]:
    """Whether ``box`` keeps every reached cell reached, and the cells reached and eroded
    after it, by labelling the whole grid (on a copy)."""
    taken = occupancy.taken.copy()
    stamped = space.cells(box.lo, box.hi)
    taken[stamped] = True
    radius = PASSAGE / 2 / space.cell
    walk_eroded = erode_near(walkable(space, taken), radius, stamped, occupancy.walk_eroded)
    eroded, reach = reachable(space, taken, PASSAGE, walk_eroded)
    return not (eroded & occupancy.reach & ~reach).any(), reach, walk_eroded


def test_a_footprint_is_kept_as_labelling_the_grid_again_says(world: World) -> None:
    """On rooms filled with random footprints (many cutting floor off, some at the grid's
    edges and over the door), each is kept or given up as a fresh labelling of the grid
    says, and what is reached and eroded afterwards is what that labelling finds."""
    rng = np.random.default_rng(11)
    catalogue = default_catalogue()
    kept = given_up = sure = 0
    for room_id in ("A.1.1.1", "A.1.2.2", "B.2.1.3"):
        space = room_free_space(world, room_id)
        occupancy = Occupancy.empty(space, door_keepout(space, world.rooms[room_id], catalogue),
                                    PASSAGE)
        (x0, y0), (nx, ny) = space.origin, space.shape
        for _ in range(150):
            lo = (x0 + rng.uniform(-0.3, nx * space.cell), y0 + rng.uniform(-0.3, ny * space.cell))
            size = rng.uniform(0.1, 2.0, 2)
            box = Box((*lo, 0.0), (lo[0] + size[0], lo[1] + size[1], 0.0))
            expected, reach, walk_eroded = labelled(space, occupancy, box)
            sure += placing._keeps_reach(space, occupancy.reach, PASSAGE / 2 / space.cell,
                                         space.cells(box.lo, box.hi))
            assert occupancy.try_stamp(space, box, 0.1, PASSAGE) == expected
            if expected:
                assert np.array_equal(occupancy.reach, reach)
                assert np.array_equal(occupancy.walk_eroded, walk_eroded)
                kept += 1
            else:
                given_up += 1
    assert kept > 50 and given_up > 50 and sure > 50  # the ring settled many
