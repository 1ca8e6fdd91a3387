"""Search areas on a scanned site's open ground: ground the scan saw (cells holding points,
small gaps closed), clear of blocks by ``CLEARANCE``; or one line saying why there is none.

The areas' grid is the voxel's. On a site of more than ``MAX_RASTER`` voxel columns it covers
a window of that many around the middle of the ground the scan saw, where the areas go (each
next one is placed nearest the last), so that its memory does not grow with the site.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy import ndimage

from astralis_des.errors import InputError
from astralis_des.importers.areas import MIN_SIZE, Area, Level, place_areas
from astralis_des.importers.cloudbuild import AREA_HEIGHT, Blocks
from astralis_des.importers.density import MAX_RASTER
from astralis_des.importers.options import ImportOptions
from astralis_des.importers.survey import Survey

CLEARANCE = 1.0  # m kept between an area and the nearest block


def cloud_areas(blocks: Blocks, shape: tuple[int, int], voxel: float, found: Survey,
                opts: ImportOptions, path: Path, notes: list[str]) -> list[Area]:
    """Up to ``opts.areas`` areas, smaller ones said in ``notes``; none: an InputError that
    gives what the scan covers and what would work."""
    if opts.areas == 0:
        return []
    lo, plan = _window(blocks, shape, voxel)
    seen = _seen(blocks, lo, plan, voxel)
    blocked = np.zeros((int(plan[0]), int(plan[1])), dtype=bool)
    inside = np.all((blocks.blocked >= lo) & (blocks.blocked < lo + plan), axis=1)
    blocked[blocks.blocked[inside, 0] - lo[0], blocks.blocked[inside, 1] - lo[1]] = True
    clear = max(math.ceil(CLEARANCE / voxel), 1)
    near = ndimage.maximum_filter(blocked, size=2 * clear + 1)  # a square dilation, separable
    free = seen & ~near
    areas = [_shifted(a, lo * voxel) for a in place_areas(
        [Level(0.0, free)], voxel, opts.areas, opts.area_size, lambda z, si, sj: AREA_HEIGHT)]
    if not areas:
        raise InputError(_none(found, seen, free, voxel, opts), file=path)
    small = [a for a in areas if a.hi[0] - a.lo[0] < opts.area_size - 1e-6]
    if small:
        side = small[0].hi[0] - small[0].lo[0]
        notes.append(f"areas {', '.join(a.id for a in small)} are {side:g} x {side:g} m, "
                     f"smaller than --area-size {opts.area_size:g}: no more open ground")
    return areas


def _window(blocks: Blocks, shape: tuple[int, int], voxel: float
            ) -> tuple[np.ndarray, np.ndarray]:
    """The corner and shape (voxel columns) of the areas' grid: the whole site, or a window of
    ``MAX_RASTER`` columns round the middle of what the scan saw."""
    site = np.array(shape, dtype=np.int64)
    side = math.isqrt(MAX_RASTER)
    if int(site.prod()) <= MAX_RASTER or not len(blocks.seen):
        return np.zeros(2, dtype=np.int64), site
    middle = ((blocks.seen.mean(axis=0) + 0.5) * blocks.seen_cell / voxel).astype(np.int64)
    plan = np.minimum(site, side)
    lo = np.clip(middle - plan // 2, 0, site - plan)
    return lo, plan


def _shifted(area: Area, by: np.ndarray) -> Area:
    dx, dy = (float(v) for v in by)
    return replace(area, lo=(round(area.lo[0] + dx, 3), round(area.lo[1] + dy, 3), area.lo[2]),
                   hi=(round(area.hi[0] + dx, 3), round(area.hi[1] + dy, 3), area.hi[2]))


def _seen(blocks: Blocks, lo: np.ndarray, size: np.ndarray, cell: float) -> np.ndarray:
    """``size``-shaped, from voxel column ``lo``: is the ground under each cell's middle in a
    cell the scan saw?"""
    coarse = blocks.seen_cell
    plan = (int(size[0]), int(size[1]))
    if not len(blocks.seen):
        return np.zeros(plan, dtype=bool)
    seen = np.zeros(tuple(int(n) for n in blocks.seen.max(axis=0) + 1), dtype=bool)
    seen[blocks.seen[:, 0], blocks.seen[:, 1]] = True
    seen = ndimage.binary_closing(seen, np.ones((3, 3), dtype=bool))
    centre = ((np.indices(plan) + lo[:, None, None] + 0.5) * cell / coarse).astype(np.int64)
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
