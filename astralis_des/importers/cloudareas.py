"""Search areas on a scanned site's open ground: ground the scan saw (cells holding points,
small gaps closed), clear of blocks by ``CLEARANCE``; or one line saying why there is none.

The areas' grid is the voxel's, coarsened to a multiple of it where the site would need more
than ``MAX_RASTER`` cells.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy import ndimage

from astralis_des.errors import InputError
from astralis_des.importers.areas import MIN_SIZE, Area, Level, place_areas
from astralis_des.importers.cloudbuild import AREA_HEIGHT, Blocks
from astralis_des.importers.density import raster_cell
from astralis_des.importers.options import ImportOptions
from astralis_des.importers.survey import Survey

CLEARANCE = 1.0  # m kept between an area and the nearest block


def cloud_areas(blocks: Blocks, shape: tuple[int, int], voxel: float, found: Survey,
                opts: ImportOptions, path: Path, notes: list[str]) -> list[Area]:
    """Up to ``opts.areas`` areas, smaller ones said in ``notes``; none: an InputError that
    gives what the scan covers and what would work."""
    if opts.areas == 0:
        return []
    cell = raster_cell(voxel, np.array(shape) * voxel)
    every = round(cell / voxel)
    plan = (math.ceil(shape[0] / every), math.ceil(shape[1] / every))
    seen = _seen(blocks, plan, cell)
    blocked = np.zeros(plan, dtype=bool)
    blocked[blocks.blocked[:, 0] // every, blocks.blocked[:, 1] // every] = True
    clear = max(math.ceil(CLEARANCE / cell), 1)
    near = ndimage.maximum_filter(blocked, size=2 * clear + 1)  # a square dilation, separable
    free = seen & ~near
    areas = place_areas([Level(0.0, free)], cell, opts.areas, opts.area_size,
                        lambda z, si, sj: AREA_HEIGHT)
    if not areas:
        raise InputError(_none(found, seen, free, cell, opts), file=path)
    small = [a for a in areas if a.hi[0] - a.lo[0] < opts.area_size - 1e-6]
    if small:
        side = small[0].hi[0] - small[0].lo[0]
        notes.append(f"areas {', '.join(a.id for a in small)} are {side:g} x {side:g} m, "
                     f"smaller than --area-size {opts.area_size:g}: no more open ground")
    return areas


def _seen(blocks: Blocks, plan: tuple[int, int], cell: float) -> np.ndarray:
    """``plan``-shaped: is the ground under each cell's middle in a cell the scan saw?"""
    coarse = blocks.seen_cell
    if not len(blocks.seen):
        return np.zeros(plan, dtype=bool)
    seen = np.zeros(tuple(int(n) for n in blocks.seen.max(axis=0) + 1), dtype=bool)
    seen[blocks.seen[:, 0], blocks.seen[:, 1]] = True
    seen = ndimage.binary_closing(seen, np.ones((3, 3), dtype=bool))
    centre = ((np.indices(plan) + 0.5) * cell / coarse).astype(np.int64)
    inside = (centre[0] < seen.shape[0]) & (centre[1] < seen.shape[1])
    fine = np.zeros(plan, dtype=bool)
    fine[inside] = seen[centre[0][inside], centre[1][inside]]
    return fine


def _none(found: Survey, seen: np.ndarray, free: np.ndarray, cell: float,
          opts: ImportOptions) -> str:
    """Why no area fits, measured, and what would work."""
    width, depth = (float(v) for v in found.hi[:2] - found.lo[:2])
    cover = (f"{found.kept:,} point{'s' * (found.kept != 1)} over {width:,.1f} x "
             f"{depth:,.1f} m")
    if min(width, depth) < MIN_SIZE:
        return (f"too small for a search area: {cover}; an area needs at least "
                f"{MIN_SIZE:g} x {MIN_SIZE:g} m of ground the scan saw, and nothing smaller "
                "is searched")
    saw = float(seen.sum()) * cell * cell
    open_ground = float(free.sum()) * cell * cell
    fill = "; --fill none blocks only where points are" if opts.fill != "none" else ""
    return (f"no open ground of {MIN_SIZE:g} x {MIN_SIZE:g} m for a search area: {cover}, "
            f"the scan saw {saw:,.0f} m^2 of ground and {open_ground:,.0f} m^2 of it is "
            f"more than {CLEARANCE:g} m from a block, in no square of {MIN_SIZE:g} m"
            f"{fill}")
