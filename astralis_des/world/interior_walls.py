"""An interior's walls, floors and roof, made from its places and doors as a built-in
building's are from its plan: whatever of the building's bounds (its places' bounds and a
wall's thickness round them) is no place of a storey, no doorway and no stairwell shaft is wall
on that storey, up to the slab of the storey above; a doorway's wall starts over the door.

So a corrected world file (a place moved, a door added) is built as corrected, and robots
route by the places and doors, as in the built-in buildings, not round a scan's voxels (which
leave a door narrower than it is by up to a voxel on each side).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from astralis_des.world.geometry import Box, inside_polygon
from astralis_des.world.parts import Solid
from astralis_des.world.spec import InteriorSpec

CELL = 0.05  # m, the grid walls are made on
WALL = 0.2  # m, the outer walls' thickness (round the places' bounds)
SLAB = 0.2  # m, a floor's or the roof's thickness
THROUGH = 0.4  # m either side of a door's middle that its doorway cuts through walls
BoolArray = NDArray[np.bool_]


def interior_bounds(spec: InteriorSpec) -> tuple[tuple[float, float], tuple[float, float]]:
    """The building's outer bounds in the plane: its places' and a wall round them."""
    xy = np.concatenate([np.asarray(p.outline, dtype=float) for p in spec.places])
    lo, hi = xy.min(axis=0) - WALL, xy.max(axis=0) + WALL
    return (float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1]))


def interior_solids(spec: InteriorSpec) -> list[Solid]:
    """The walls, floor slabs and roof of ``spec``'s building."""
    lo, hi = (np.asarray(v) for v in interior_bounds(spec))
    shape = tuple(np.ceil((hi - lo) / CELL).astype(int))
    i, j = np.indices(shape)
    centres = np.column_stack([i.ravel(), j.ravel()]) * CELL + lo + CELL / 2
    solids: list[Solid] = []
    shaft = np.zeros(shape, dtype=bool)
    levels = spec.storeys
    for n, storey in enumerate(levels):
        places = [p for p in spec.places if p.storey == storey.level]
        floor = np.zeros(shape, dtype=bool)
        for place in places:
            floor |= inside_polygon(centres, np.asarray(place.outline)).reshape(shape)
        gaps: dict[float, BoolArray] = {}  # by the doors' heights
        for door in spec.doors:
            if str(storey.level) in (name.split(".")[1] for name in door.between
                                     if "." in name):
                cut = gaps.setdefault(door.height, np.zeros(shape, dtype=bool))
                cut |= _doorway(door.at, door.across, door.width, lo, shape)
        top = levels[n + 1].z - SLAB if n + 1 < len(levels) else storey.z + storey.height - SLAB
        wall = ~floor & ~shaft
        label = f"{spec.group}.{storey.level}"
        doorways = np.zeros(shape, dtype=bool)
        for height, cut in sorted(gaps.items()):
            solids += [Solid("wall", b, label) for b in
                       _boxes(wall & cut & ~doorways, lo, min(storey.z + height, top), top)]
            doorways |= cut
        solids += [Solid("wall", b, label) for b in _boxes(wall & ~doorways, lo, storey.z, top)]
        if n > 0:  # its floor, open over a shaft where this storey has no place
            solids += [Solid("slab", b, f"{label} floor") for b in
                       _boxes(~(shaft & ~floor), lo, storey.z - SLAB, storey.z)]
        shaft = (shaft & ~floor) | _stairwells(spec, storey.level, centres, shape)
    last = levels[-1]
    solids += [Solid("slab", b, f"{spec.group} roof") for b in
               _boxes(np.ones(shape, dtype=bool), lo, last.z + last.height - SLAB,
                      last.z + last.height)]
    return solids


def _stairwells(spec: InteriorSpec, level: int, centres: np.ndarray,
                shape: tuple[int, ...]) -> BoolArray:
    """The stairwells of storey ``level``: open to the storeys above (their shaft)."""
    out = np.zeros(shape, dtype=bool)
    for place in spec.places:
        if place.storey == level and place.kind == "stairwell":
            out |= inside_polygon(centres, np.asarray(place.outline)).reshape(shape)
    return out


def _doorway(at: tuple[float, float], across: str, width: float, lo: np.ndarray,
             shape: tuple[int, ...]) -> BoolArray:
    """The cells of a doorway: ``width`` along its wall, ``THROUGH`` either side of its
    middle across it (through a thick wall, and a found door's middle may be off the wall's)."""
    axis = 0 if across == "x" else 1
    half = np.array([THROUGH, THROUGH])
    half[1 - axis] = width / 2
    a = np.floor((np.asarray(at) - half - lo) / CELL + 0.5).astype(int)
    b = np.floor((np.asarray(at) + half - lo) / CELL + 0.5).astype(int)
    out = np.zeros(shape, dtype=bool)
    out[max(a[0], 0):max(b[0], 0), max(a[1], 0):max(b[1], 0)] = True
    return out


def _boxes(mask: BoolArray, lo: np.ndarray, z0: float, z1: float) -> list[Box]:
    """``mask``'s cells merged into few rectangles (runs along y, stacked along x), each a box
    from ``z0`` to ``z1``."""
    if z1 <= z0 or not mask.any():
        return []
    open_runs: dict[tuple[int, int], int] = {}  # (j0, j1) -> the row it started on
    rects: list[tuple[int, int, int, int]] = []
    for i in range(mask.shape[0] + 1):
        row = mask[i] if i < mask.shape[0] else np.zeros(mask.shape[1], dtype=bool)
        edges = np.flatnonzero(np.diff(np.concatenate([[0], row.astype(np.int8), [0]])))
        runs = set(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))
        for run in [r for r in open_runs if r not in runs]:
            rects.append((open_runs.pop(run), run[0], i, run[1]))
        for run in runs - set(open_runs):
            open_runs[run] = i
    return [Box((float(lo[0] + i0 * CELL), float(lo[1] + j0 * CELL), z0),
                (float(lo[0] + i1 * CELL), float(lo[1] + j1 * CELL), z1))
            for i0, j0, i1, j1 in sorted(rects)]
