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

from astralis_des.importers.sparse import keyed
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
    """The ground surface ``z = height(x, y)`` on a grid (a plane for RANSAC), and which
    points are ground."""

    method: str
    origin: FloatArray  # (2,) corner of the grid
    cell: float
    heights: FloatArray  # (nx, ny) ground height of each cell's centre
    plane: tuple[float, float, float] | None = None  # z = a x + b y + c (ransac)

    def height(self, xy: FloatArray) -> FloatArray:
        """Bilinear ground height at each ``(x, y)``; the edge value beyond the grid."""
        u = (np.asarray(xy)[:, :2] - self.origin) / self.cell - 0.5
        return np.asarray(ndimage.map_coordinates(self.heights, [u[:, 0], u[:, 1]], order=1,
                                                  mode="nearest"))

    def is_ground(self, xyz: FloatArray, classification: NDArray[np.uint8] | None,
                  surface: FloatArray | None = None) -> NDArray[np.bool_]:
        """``(N,)``: the points of class 2 (``classification``), within ``RANSAC_TOLERANCE``
        of the plane (``ransac``), or on the surface's lower envelope (``grid``);
        ``surface`` is :meth:`height` at ``xyz``, when the caller has it."""
        if self.method == "classification":
            assert classification is not None
            return np.asarray(classification == GROUND_CLASS)
        if self.plane is not None:
            a, b, c = self.plane
            return np.asarray(np.abs(xyz[:, 2] - (a * xyz[:, 0] + b * xyz[:, 1] + c))
                              <= RANSAC_TOLERANCE)
        below = self.height(xyz) if surface is None else surface
        return np.asarray(xyz[:, 2] <= below + TOLERANCE)

    @property
    def relief(self) -> float:
        """m between the 1st and 99th percentile of the ground's heights: what flattening the
        ground to ``z = 0`` removes."""
        lo, hi = np.percentile(self.heights, [1, 99])
        return float(hi - lo)


class Minima:
    """The lowest z of each cell of a grid (``inf`` where none), folded in chunk by chunk."""

    def __init__(self, origin: FloatArray, cell: float, shape: tuple[int, int]) -> None:
        self.origin, self.cell = np.asarray(origin, dtype=float), cell
        self.lowest = np.full(shape, np.inf)

    def add(self, xyz: FloatArray, mask: NDArray[np.bool_] | None = None) -> None:
        pick = xyz if mask is None else xyz[mask]
        if not len(pick):
            return
        index = np.floor((pick[:, :2] - self.origin) / self.cell).astype(np.int64)
        np.clip(index, 0, np.array(self.lowest.shape) - 1, out=index)
        flat = index[:, 0] * self.lowest.shape[1] + index[:, 1]
        keys, low = keyed(flat, pick[:, 2], "min")
        view = self.lowest.reshape(-1)
        view[keys] = np.minimum(view[keys], low)


Method = Callable[[Minima, np.random.Generator], Ground]
METHODS: Registry[str, Method] = Registry("ground method")


def find_ground(xyz: FloatArray, classification: NDArray[np.uint8] | None, method: str,
                rng: np.random.Generator, cell: float = CELL) -> Ground:
    """The ground of a whole cloud by ``method`` (``auto``: the classification when it has
    ground points, else the grid minimum); :func:`ground_of` for a cloud seen in chunks."""
    if method == "auto":
        has_class = classification is not None and bool(np.any(classification == GROUND_CLASS))
        method = "classification" if has_class else "grid"
    origin = xyz[:, :2].min(axis=0)
    shape = grid_size(xyz[:, :2].max(axis=0), origin, cell)
    minima = Minima(origin, cell, shape)
    if method == "classification":
        if classification is None or not np.any(classification == GROUND_CLASS):
            raise ValueError("the cloud has no points classified as ground (class 2)")
        minima.add(xyz, classification == GROUND_CLASS)
    else:
        minima.add(xyz)
    return ground_of(minima, method, rng)


def grid_size(hi: FloatArray, origin: FloatArray, cell: float) -> tuple[int, int]:
    """Cells of ``cell`` from ``origin`` to the one holding ``hi``."""
    index = np.floor((np.asarray(hi) - origin) / cell).astype(np.int64)
    return int(index[0]) + 1, int(index[1]) + 1


def ground_of(minima: Minima, method: str, rng: np.random.Generator) -> Ground:
    """The ground by ``method`` from the cells' lowest points (of the ground class, for
    ``classification``)."""
    ground = METHODS.get(method)(minima, rng)
    log.info("ground by %s, relief %.1f m", ground.method, ground.relief)
    return ground


def _filled(lowest: FloatArray) -> FloatArray:
    """Empty cells take the value of the nearest filled one."""
    empty = ~np.isfinite(lowest)
    if not empty.any():
        return lowest
    if empty.all():
        return np.zeros_like(lowest)
    index = ndimage.distance_transform_edt(empty, return_distances=False, return_indices=True)
    return np.asarray(lowest[tuple(index)])


def _objects(surface: FloatArray, cell: float) -> NDArray[np.bool_]:
    """Cells of the minimum surface that openings of growing windows lower by more than the
    terrain's ``SLOPE`` allows: what stands on the ground."""
    objects = np.zeros(surface.shape, dtype=bool)
    for radius in range(1, max(round(WINDOW / cell / 2), 1) + 1):
        opened = ndimage.grey_opening(surface, size=(2 * radius + 1, 2 * radius + 1))
        objects |= surface - opened > SLOPE * radius * cell
    return objects


@METHODS.register("classification")
def by_classification(minima: Minima, rng: np.random.Generator) -> Ground:
    return Ground("classification", minima.origin, minima.cell, _filled(minima.lowest))


@METHODS.register("grid")
def by_grid_minimum(minima: Minima, rng: np.random.Generator) -> Ground:
    lowest = _filled(minima.lowest)
    objects = _objects(lowest, minima.cell)
    heights = _filled(np.where(objects, np.inf, lowest)) if not objects.all() else lowest
    return Ground("grid", minima.origin, minima.cell, heights)


@METHODS.register("ransac")
def by_ransac_plane(minima: Minima, rng: np.random.Generator) -> Ground:
    origin, cell, lowest = minima.origin, minima.cell, minima.lowest
    ci, cj = np.nonzero(np.isfinite(lowest))
    seeds = np.column_stack([origin[0] + (ci + 0.5) * cell, origin[1] + (cj + 0.5) * cell,
                             lowest[ci, cj]])
    plane = _ransac_plane(seeds, rng)
    a, b, c = plane  # z = a x + b y + c
    gx = origin[0] + (np.arange(lowest.shape[0]) + 0.5) * cell
    gy = origin[1] + (np.arange(lowest.shape[1]) + 0.5) * cell
    heights = a * gx[:, None] + b * gy[None, :] + c
    return Ground("ransac", origin, cell, heights, plane)


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
