"""The ground of a point cloud: which points are ground, and the ground's height anywhere.

Three ways, one result (:class:`Ground`):

- ``classification``: the points of ASPRS class 2, when the file has them; the surface is the
  grid minimum of those points.
- ``grid``: the lowest point of each ``CELL`` cell is the surface, except where something
  stands: a simple morphological filter (after Pingel et al.'s SMRF) opens the surface with
  windows growing to ``WINDOW``, and a cell that drops by more than ``SLOPE`` times the window's
  radius is an object (a roof, a canopy), filled from the nearest ground cell. The ground
  points are those on that lower envelope, within ``TOLERANCE``.
- ``ransac``: one plane fitted by RANSAC to the cells' minima (a hall, a car park, a flat
  site); the points within ``RANSAC_TOLERANCE`` of it are ground. Draws come from a seeded
  generator.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from astralis_des.registry import Registry
from astralis_des.world.geometry import FloatArray

log = logging.getLogger(__name__)

CELL = 1.0  # m, the ground grid
WINDOW = 20.0  # m: the widest roof or canopy the filter removes
SLOPE = 0.15  # rise over run the terrain may have; steeper drops are objects' edges
TOLERANCE = 0.01  # m above the lower envelope that is still ground
RANSAC_ITERATIONS = 200
RANSAC_TOLERANCE = 0.05  # m from the plane that is still ground
GROUND_CLASS = 2  # ASPRS LAS classification


@dataclass(frozen=True)
class Ground:
    """Ground points and the ground surface ``z = height(x, y)``, on a grid or a plane."""

    method: str
    mask: NDArray[np.bool_]  # (N,) true for ground points
    origin: FloatArray  # (2,) corner of the grid
    cell: float
    heights: FloatArray  # (nx, ny) ground height of each cell's centre

    def height(self, xy: FloatArray) -> FloatArray:
        """Bilinear ground height at each ``(x, y)``; the edge value beyond the grid."""
        u = (np.asarray(xy)[:, :2] - self.origin) / self.cell - 0.5
        return np.asarray(ndimage.map_coordinates(self.heights, [u[:, 0], u[:, 1]], order=1,
                                                  mode="nearest"))

    @property
    def share(self) -> float:
        return float(self.mask.mean()) if len(self.mask) else 0.0

    @property
    def relief(self) -> float:
        """m between the 1st and 99th percentile of the ground's heights: what flattening the
        ground to ``z = 0`` removes."""
        lo, hi = np.percentile(self.heights, [1, 99])
        return float(hi - lo)


Method = Callable[[FloatArray, "NDArray[np.uint8] | None", np.random.Generator], Ground]
METHODS: Registry[str, Method] = Registry("ground method")


def find_ground(xyz: FloatArray, classification: NDArray[np.uint8] | None, method: str,
                rng: np.random.Generator) -> Ground:
    """The ground by ``method`` (``auto``: the classification when it has ground points,
    else the grid minimum)."""
    if method == "auto":
        has_class = classification is not None and bool(np.any(classification == GROUND_CLASS))
        method = "classification" if has_class else "grid"
    ground = METHODS.get(method)(xyz, classification, rng)
    log.info("ground by %s: %.1f%% of the points, relief %.1f m", ground.method,
             100 * ground.share, ground.relief)
    return ground


def _cells(xy: FloatArray, origin: FloatArray) -> tuple[NDArray[np.int64], tuple[int, int]]:
    index = np.floor((xy - origin) / CELL).astype(np.int64)
    shape = (int(index[:, 0].max()) + 1, int(index[:, 1].max()) + 1)
    return index, shape


def _minima(xyz: FloatArray, index: NDArray[np.int64], shape: tuple[int, int]) -> FloatArray:
    """Lowest z of each cell (inf where empty), by sorting: ``minimum.at`` is slower."""
    flat = index[:, 0] * shape[1] + index[:, 1]
    order = np.lexsort((xyz[:, 2], flat))
    first = np.ones(len(order), dtype=bool)
    first[1:] = flat[order][1:] != flat[order][:-1]
    lowest = np.full(shape[0] * shape[1], np.inf)
    lowest[flat[order][first]] = xyz[order[first], 2]
    return lowest.reshape(shape)


def _filled(lowest: FloatArray) -> FloatArray:
    """Empty cells take the value of the nearest filled one."""
    empty = ~np.isfinite(lowest)
    if not empty.any():
        return lowest
    index = ndimage.distance_transform_edt(empty, return_distances=False, return_indices=True)
    return np.asarray(lowest[tuple(index)])


def _surface(xyz: FloatArray, mask: NDArray[np.bool_] | None) -> tuple[FloatArray, FloatArray]:
    """Origin and grid minimum of the points (of ``mask``), empty cells filled."""
    origin = xyz[:, :2].min(axis=0)
    index, shape = _cells(xyz[:, :2], origin)
    pick = slice(None) if mask is None else mask
    return origin, _filled(_minima(xyz[pick], index[pick], shape))


def _objects(surface: FloatArray) -> NDArray[np.bool_]:
    """Cells of the minimum surface that openings of growing windows lower by more than the
    terrain's ``SLOPE`` allows: what stands on the ground."""
    objects = np.zeros(surface.shape, dtype=bool)
    for radius in range(1, max(round(WINDOW / CELL / 2), 1) + 1):
        opened = ndimage.grey_opening(surface, size=(2 * radius + 1, 2 * radius + 1))
        objects |= surface - opened > SLOPE * radius * CELL
    return objects


@METHODS.register("classification")
def by_classification(xyz: FloatArray, classification: NDArray[np.uint8] | None,
                      rng: np.random.Generator) -> Ground:
    if classification is None or not np.any(classification == GROUND_CLASS):
        raise ValueError("the cloud has no points classified as ground (class 2)")
    mask = classification == GROUND_CLASS
    origin, heights = _surface(xyz, mask)
    return Ground("classification", mask, origin, CELL, heights)


@METHODS.register("grid")
def by_grid_minimum(xyz: FloatArray, classification: NDArray[np.uint8] | None,
                    rng: np.random.Generator) -> Ground:
    origin, lowest = _surface(xyz, None)
    objects = _objects(lowest)
    heights = _filled(np.where(objects, np.inf, lowest)) if not objects.all() else lowest
    ground = Ground("grid", np.zeros(len(xyz), dtype=bool), origin, CELL, heights)
    mask = xyz[:, 2] <= ground.height(xyz) + TOLERANCE
    return Ground("grid", mask, origin, CELL, heights)


@METHODS.register("ransac")
def by_ransac_plane(xyz: FloatArray, classification: NDArray[np.uint8] | None,
                    rng: np.random.Generator) -> Ground:
    origin = xyz[:, :2].min(axis=0)
    index, shape = _cells(xyz[:, :2], origin)
    lowest = _minima(xyz, index, shape)
    ci, cj = np.nonzero(np.isfinite(lowest))
    seeds = np.column_stack([origin[0] + (ci + 0.5) * CELL, origin[1] + (cj + 0.5) * CELL,
                             lowest[ci, cj]])
    plane = _ransac_plane(seeds, rng)
    a, b, c = plane  # z = a x + b y + c
    gx = origin[0] + (np.arange(shape[0]) + 0.5) * CELL
    gy = origin[1] + (np.arange(shape[1]) + 0.5) * CELL
    heights = a * gx[:, None] + b * gy[None, :] + c
    mask = np.abs(xyz[:, 2] - (a * xyz[:, 0] + b * xyz[:, 1] + c)) <= TOLERANCE
    return Ground("ransac", mask, origin, CELL, heights)


def _ransac_plane(points: FloatArray, rng: np.random.Generator) -> tuple[float, float, float]:
    """``(a, b, c)`` of the plane ``z = a x + b y + c`` with the most inliers, refitted to
    them by least squares. Only planes within 30 degrees of level are tried."""
    if len(points) < 3:
        return (0.0, 0.0, float(points[:, 2].min()) if len(points) else 0.0)
    triples = rng.integers(0, len(points), size=(RANSAC_ITERATIONS, 3))
    p = points[triples]  # (I, 3, 3)
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    length = np.linalg.norm(normal, axis=1)
    level = np.abs(normal[:, 2]) > np.cos(np.radians(30)) * np.where(length > 0, length, np.inf)
    best, best_count = None, -1
    for k in np.flatnonzero(level):
        n = normal[k] / length[k]
        distance = np.abs((points - p[k, 0]) @ n)
        count = int((distance <= RANSAC_TOLERANCE).sum())
        if count > best_count:
            best, best_count = distance <= RANSAC_TOLERANCE, count
    inliers = points[best] if best is not None else points
    design = np.column_stack([inliers[:, 0], inliers[:, 1], np.ones(len(inliers))])
    coef, *_ = np.linalg.lstsq(design, inliers[:, 2], rcond=None)
    return (float(coef[0]), float(coef[1]), float(coef[2]))
