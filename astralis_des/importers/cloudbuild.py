"""The pass over a cloud that builds its world: heights above the ground, what stands (blocks),
what the scan saw (for the search areas) and a sample of points for the replay.

Blocks are folded in chunk by chunk: the highest point of each column (``fill: columns``) or
the set of voxels holding points (``none``, and vegetation's canopy), as sparse keys.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from astralis_des.importers.columns import Columns
from astralis_des.importers.density import raster_cell
from astralis_des.importers.ground import Ground
from astralis_des.importers.options import ImportOptions
from astralis_des.importers.source import Cloud
from astralis_des.importers.sparse import IntArray, KeySet, pack, unpack
from astralis_des.importers.survey import Survey
from astralis_des.importers.voxels import boxes_from_columns, boxes_from_indices, voxel_index
from astralis_des.world.geometry import FloatArray

VEGETATION_CLASSES = (3, 4, 5)  # ASPRS low, medium, high vegetation: drawn where it is
NOISE_CLASSES = (7, 18)  # ASPRS low and high noise: left out
MIN_HEIGHT = 0.3  # m above the ground: lower points are the ground's own clutter (grass, kerbs)
AREA_HEIGHT = 10.0  # m: an area on the ground is searched up to this height
MAX_CLOSE = 5  # cells of grey closing at most
SEEN_CELL = 2.0  # m: ground counts as seen by the scan in cells of this size holding points


@dataclass
class Blocks:
    """What the build pass made."""

    boxes: IntArray  # (K, 6) voxel index ranges
    blocked: IntArray  # (M, 2) voxel columns with a block below AREA_HEIGHT
    seen: IntArray  # (S, 2) cells of ``seen_cell`` that hold points
    seen_cell: float
    ground_points: int
    standing: int
    canopy: int
    cloud: NDArray[np.float32]  # (C, 3) the replay's sample, world frame
    colors: NDArray[np.uint8] | None
    points: NDArray[np.float32] | None = None  # (N, 3) every kept point, world frame (indoor)


def build(cloud: Cloud, found: Survey, ground: Ground, origin: FloatArray,
          shape: tuple[int, int], voxel: float, fill: str, opts: ImportOptions,
          rng: np.random.Generator) -> Blocks:
    seen_cell = max(SEEN_CELL, voxel, 2 * found.spacing,
                    raster_cell(voxel, np.array(shape) * voxel))
    # A closing as wide as the points are apart fills the holes between the returns of one
    # roof; points further apart than MAX_CLOSE voxels leave holes no closing should fill.
    gap = max(math.ceil(found.spacing / voxel), 1)
    close = gap if gap <= MAX_CLOSE else 1
    sample = _sample(found.kept, opts.cloud_points, rng)
    picked_xyz = np.empty((len(sample), 3), dtype=np.float32)
    picked_rgb = np.empty((len(sample), 3), dtype=np.uint8) if cloud.colors is not None \
        else None
    columns = Columns(shape) if fill == "columns" else None
    solid, crowns, seen = KeySet(), KeySet(), KeySet()
    counts = {"ground": 0, "standing": 0, "canopy": 0}
    top = np.array(shape) - 1
    done = 0
    every = np.empty((found.kept, 3), dtype=np.float32) if opts.indoor else None
    for lo, hi, m in found.metres.chunks():
        keep = found.keep[lo:hi]
        m = m[keep]
        classes = cloud.classification[lo:hi][keep] if cloud.classification is not None \
            else None
        surface = ground.height(m)
        height = m[:, 2] - surface
        on_ground = ground.is_ground(m, classes, surface)
        standing = ~on_ground & (height > MIN_HEIGHT)
        canopy = np.zeros(len(m), dtype=bool)
        if classes is not None:
            standing &= ~np.isin(classes, NOISE_CLASSES)
            canopy = standing & np.isin(classes, VEGETATION_CLASSES)
        counts["ground"] += int(on_ground.sum())
        counts["standing"] += int(standing.sum())
        counts["canopy"] += int(canopy.sum())
        local = m[:, :2] - origin
        for mask, into in ((standing & ~canopy, solid), (canopy, crowns)):
            cells = np.minimum(np.floor(local[mask] / voxel).astype(np.int64), top)
            if into is solid and columns is not None:
                columns.add(cells, height[mask])
                continue
            k = voxel_index(height[mask][:, None], voxel)[:, 0]
            into.add(pack(np.column_stack([cells, k])))
        seen.add(pack(np.floor(local / seen_cell).astype(np.int64)))
        a, b = np.searchsorted(sample, [done, done + len(m)])
        rows = sample[a:b] - done
        picked_xyz[a:b] = np.column_stack([local[rows], height[rows]])
        if every is not None:
            every[done:done + len(m)] = np.column_stack([local, height])
        if picked_rgb is not None and cloud.colors is not None:
            picked_rgb[a:b] = cloud.colors[lo:hi][keep][rows]
        done += len(m)
    boxes, blocked = _solids(columns, solid, voxel, close)
    crown = unpack(crowns.result(), 3)
    if len(crown):  # only where its points are: a walker passes under a tree's crown
        boxes = np.concatenate([boxes, boxes_from_indices(crown)])
        blocked = np.concatenate([blocked, crown[crown[:, 2] * voxel < AREA_HEIGHT, :2]])
    return Blocks(boxes, blocked, unpack(seen.result(), 2), seen_cell, counts["ground"],
                  counts["standing"], counts["canopy"], picked_xyz, picked_rgb, every)


def _solids(columns: Columns | None, solid: KeySet, voxel: float,
            close: int) -> tuple[IntArray, IntArray]:
    """Merged boxes of what stands, and the columns it blocks below ``AREA_HEIGHT``."""
    if columns is not None:
        i, j, tops = columns.tops(voxel, close)
        return boxes_from_columns(i, j, tops), np.column_stack([i, j])[tops > 0]
    index = unpack(solid.result(), 3)
    low = index[index[:, 2] * voxel < AREA_HEIGHT]
    return boxes_from_indices(index), low[:, :2]


def _sample(n: int, keep: int, rng: np.random.Generator) -> NDArray[np.int64]:
    if keep >= n:
        return np.arange(n)
    return np.sort(rng.choice(n, size=keep, replace=False))
