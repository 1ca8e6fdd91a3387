"""A point cloud becomes a world: units to metres, recentred, the ground found and flattened
to ``z = 0``, what stands on it voxelised into blocks, search areas on the open ground, and a
downsampled cloud for the replay.

Heights are heights above the ground (a normalised height model): the physics ground is a
plane, so the terrain's relief (reported) is flattened, and whatever stands on it keeps its
height. ``fill: columns`` (aerial scans) makes each occupied column solid down to the ground,
since an aerial scanner sees the roof and not what is under it; ``none`` keeps the voxels the
points fall in (terrestrial and indoor scans, which see walls). A classified cloud (ASPRS
classes) is used as classified: ground (2) is the ground, buildings (6) and unclassified points
stand as the fill says (an aerial scan's building: a solid from its roof down), vegetation
(3-5) is canopy kept where its points are (a UAV plans round a crown, a walker passes under
it), noise (7, 18) is left out.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
from scipy import ndimage

from astralis_des.errors import InputError
from astralis_des.importers.areas import Area, Level, place_areas
from astralis_des.importers.ground import GROUND_CLASS, find_ground
from astralis_des.importers.options import Built, ImportOptions
from astralis_des.importers.pointcloud import spacing
from astralis_des.importers.source import Cloud, finite_rows, unit_scale
from astralis_des.importers.voxels import (
    boxes_from_columns,
    boxes_from_indices,
    column_tops,
    grid_shape,
    unique_rows,
    voxel_index,
)
from astralis_des.world.geometry import FloatArray

log = logging.getLogger(__name__)

VEGETATION_CLASSES = (3, 4, 5)  # ASPRS low, medium, high vegetation: drawn where it is
NOISE_CLASSES = (7, 18)  # ASPRS low and high noise: left out
MIN_HEIGHT = 0.3  # m above the ground: lower points are the ground's own clutter (grass, kerbs)
AREA_HEIGHT = 10.0  # m: an area on the ground is searched up to this height
CLEARANCE = 1.0  # m kept between an area and the nearest block
MAX_CLOSE = 5  # cells of grey closing at most
SEEN_CELL = 2.0  # m: ground counts as seen by the scan in cells of this size holding points


def cloud_world(cloud: Cloud, path: Path, opts: ImportOptions) -> Built:
    finite = finite_rows(cloud.xyz)
    dropped = int(len(finite) - finite.sum())
    if dropped:
        log.warning("%s: dropped %d points with NaN or infinite coordinates", path, dropped)
    if not finite.any():
        raise InputError(f"no point has finite coordinates ({dropped:,} dropped)", file=path)
    xyz = cloud.xyz[finite] if dropped else cloud.xyz
    classes = cloud.classification[finite] if (
        cloud.classification is not None and dropped) else cloud.classification
    colors = cloud.colors[finite] if cloud.colors is not None and dropped else cloud.colors
    scale = unit_scale(opts.units, cloud.crs_scale) * opts.scale
    vertical = (cloud.crs_vertical if opts.units == "auto" and cloud.crs_vertical else
                unit_scale(opts.units, cloud.crs_scale)) * opts.scale
    points = xyz * np.array([scale, scale, vertical])
    del xyz
    rng = np.random.default_rng(opts.seed)
    try:
        ground = find_ground(points, classes, opts.ground, rng)
    except ValueError as exc:
        raise InputError(str(exc), file=path, key="--ground") from None
    height = points[:, 2] - ground.height(points)
    origin = points[:, :2].min(axis=0) - opts.margin
    local = points[:, :2] - origin
    del points
    extent = local.max(axis=0) + opts.margin
    shape = grid_shape(extent, opts.voxel, what="the cloud")
    site = (shape[0] * opts.voxel, shape[1] * opts.voxel)
    standing = ~ground.mask & (height > MIN_HEIGHT)
    canopy = np.zeros(len(standing), dtype=bool)
    if classes is not None:  # ASPRS classes: noise left out; vegetation is canopy (below)
        standing &= ~np.isin(classes, NOISE_CLASSES)
        canopy = standing & np.isin(classes, VEGETATION_CLASSES)
    fill = opts.fill if opts.fill != "auto" else (
        "columns" if path.suffix.lower() in (".las", ".laz") else "none")
    boxes, blocked = _blocks(local, height, standing & ~canopy, shape, opts.voxel, fill)
    if canopy.any():  # only where its points are: a walker passes under a tree's crown
        crown, under = _blocks(local, height, canopy, shape, opts.voxel, "none")
        boxes, blocked = np.concatenate([boxes, crown]), blocked | under
    areas = _areas(local, blocked, shape, opts)
    sample = _sample(len(local), opts.cloud_points, rng)
    cloud_xyz = np.column_stack([local[sample], height[sample]]).astype(np.float32)
    cloud_rgb = colors[sample] if colors is not None else None
    classified = float(np.mean(classes == GROUND_CLASS)) if classes is not None else None
    offset = (float(origin[0] / scale), float(origin[1] / scale),
              float(np.median(ground.heights) / vertical))
    source = {"kind": "cloud", "points": len(finite), "dropped": dropped,
              "units": _units_note(opts, cloud, scale), "scale": round(scale, 9), "up": "z",
              "offset": offset, "ground": ground.method,
              "ground_share": round(ground.share, 4), "relief": round(ground.relief, 2),
              "origin": _geodetic(cloud.crs_wkt, offset, vertical)}
    stats = {"ground_share": ground.share, "classified_share": classified, "fill": fill,
             "standing": int(standing.sum()), "canopy": int(canopy.sum())}
    return Built("cloud", site, opts.voxel, boxes, areas, source, "boxes",
                 floors=[0.0], cloud=cloud_xyz, cloud_colors=cloud_rgb, stats=stats)


def _geodetic(wkt: str | None, offset: tuple[float, float, float],
              vertical: float) -> dict[str, float] | None:
    """Where the world's (0, 0, 0) lies on the Earth (WGS 84), from the file's coordinate
    system (pyproj): its ``offset`` in the file's units, its height in metres."""
    if wkt is None:
        return None
    from pyproj import CRS, Transformer
    from pyproj.exceptions import CRSError, ProjError

    try:
        to_wgs84 = Transformer.from_crs(CRS.from_wkt(wkt), "EPSG:4326", always_xy=True)
        lon, lat = to_wgs84.transform(offset[0], offset[1])
    except (CRSError, ProjError) as exc:  # a system pyproj cannot take to WGS 84: no georeference
        log.warning("the file's coordinate system gives no WGS 84 position (%s): the world "
                    "is not georeferenced", exc)
        return None
    if not (math.isfinite(lat) and math.isfinite(lon)):
        return None
    return {"latitude": round(float(lat), 7), "longitude": round(float(lon), 7),
            "altitude": round(offset[2] * vertical, 3)}


def _units_note(opts: ImportOptions, cloud: Cloud, scale: float) -> str:
    if opts.units != "auto":
        return f"{opts.units} (given)"
    if cloud.crs_scale is not None:
        return cloud.crs_note
    return "m (no CRS in the file: metres assumed)"


def _blocks(xy: FloatArray, height: FloatArray, standing: np.ndarray, shape: tuple[int, ...],
            voxel: float, fill: str) -> tuple[np.ndarray, np.ndarray]:
    """Merged boxes of what stands on the ground, and the ``(nx, ny)`` cells blocked below
    ``AREA_HEIGHT``."""
    cells = np.floor(xy[standing] / voxel).astype(np.int64)
    cells = np.minimum(cells, np.array(shape[:2]) - 1)
    if fill == "columns":
        close = min(max(math.ceil(spacing(xy) / voxel), 1), MAX_CLOSE)
        tops = column_tops(cells, height[standing], (shape[0], shape[1]), voxel, close)
        return boxes_from_columns(tops), tops > 0
    index = unique_rows(np.column_stack([cells, voxel_index(height[standing][:, None],
                                                            voxel)[:, 0]]))
    blocked = np.zeros(shape[:2], dtype=bool)
    low = index[index[:, 2] * voxel < AREA_HEIGHT]
    blocked[low[:, 0], low[:, 1]] = True
    return boxes_from_indices(index), blocked


def _areas(xy: FloatArray, blocked: np.ndarray, shape: tuple[int, ...],
           opts: ImportOptions) -> list[Area]:
    """Areas on ground the scan saw (``SEEN_CELL`` cells holding points, small gaps closed),
    clear of blocks by ``CLEARANCE``."""
    if opts.areas == 0:
        return []
    coarse = max(SEEN_CELL, opts.voxel)
    cells = np.floor(xy / coarse).astype(np.int64)
    seen = np.zeros(tuple(int(n) for n in cells.max(axis=0) + 1), dtype=bool)
    seen[cells[:, 0], cells[:, 1]] = True
    seen = ndimage.binary_closing(seen, np.ones((3, 3), dtype=bool))
    centre = ((np.indices(shape[:2]) + 0.5) * opts.voxel / coarse).astype(np.int64)
    inside = (centre[0] < seen.shape[0]) & (centre[1] < seen.shape[1])
    seen_fine = np.zeros(shape[:2], dtype=bool)
    seen_fine[inside] = seen[centre[0][inside], centre[1][inside]]
    clear = max(math.ceil(CLEARANCE / opts.voxel), 1)
    near = ndimage.maximum_filter(blocked, size=2 * clear + 1)  # a square dilation, separable
    return place_areas([Level(0.0, seen_fine & ~near)], opts.voxel, opts.areas,
                       opts.area_size, lambda z, si, sj: AREA_HEIGHT)


def _sample(n: int, keep: int, rng: np.random.Generator) -> np.ndarray:
    if keep >= n:
        return np.arange(n)
    return np.sort(rng.choice(n, size=keep, replace=False))
