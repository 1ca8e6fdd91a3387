"""A storey's plan: which cells of a 2-D grid are walls, inside the building, floor, and free.

- **Walls** are tall: the points between knee and head height over the floor (``knee`` to
  ``head``) are binned in ``LAYERS`` layers, and a cell is a wall when it holds points in the
  upper half of the layers and the cells up to ``WALL_REACH`` round it (so that a sparse
  cloud's gaps do not count) have points in at least ``WALL_SHARE`` of them. A table
  (0.75 m), a chair or a low cabinet fills a layer or two and stays free, even against a wall;
  so does a tall blob shorter than ``MIN_BLOB`` every way (a standing person, a lamp, a thin
  pillar). Gaps up to ``GAP`` between wall cells (missing points, a hollow wall's inside) are
  closed.
- **Inside** is what the walls enclose once openings up to ``OUTLINE_GAP`` wide (the
  entrances) are closed: a closing with a square, so that a gap in a straight wall closes
  flush with it, then the holes filled.
- **Floor**: cells within ``FLOOR_REACH`` of a point at the storey's floor level
  (``FLOOR_BAND`` either side) that is not a wall's, holes under ``FLOOR_HOLE`` filled (the
  floor under a desk the scan missed). A stair's void or a sealed space has none.
- **Free** is inside, floor and not wall: what the rooms are cut from.

The grid covers the storey's points, padded; its cells are ``cell`` square, at least about
half the points' spacing on the surfaces (:func:`surface_spacing`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from astralis_des.importers.indoor.storeys import Storey
from astralis_des.world.geometry import FloatArray

BoolArray = NDArray[np.bool_]
KNEE, HEAD = 0.5, 1.8  # m over the floor: the slice walls are told from furniture in
LAYERS = 6  # height layers of the slice
WALL_SHARE = 0.75  # of the layers a wall's cell (with its neighbours) fills
WALL_REACH = 0.1  # m: a wall's cell counts the layers of the cells this near
MIN_BLOB = 0.5  # m, tall things shorter than this every way are not walls
GAP = 0.2  # m, gaps in walls closed
OUTLINE_GAP = 2.5  # m, the widest entrance: wider openings let the outside in
FLOOR_BAND = 0.08  # m either side of the floor level
FLOOR_REACH = 0.3  # m from a floor point that is still floor (over a threshold, under a wall)
FLOOR_HOLE = 4.0  # m², holes in the floor filled
CEILING_MARGIN = 0.1  # m under the ceiling where the slice stops at the latest
PROBE = 0.25  # m, the voxels :func:`surface_spacing` counts points in
MAX_CELLS = 1 << 25  # a storey's grid at most (a 290 m square of 5 cm cells)


@dataclass(frozen=True)
class Plan:
    """One storey's grid: ``walls``, ``inside``, ``floor`` and ``free`` cells; cell ``(i, j)``
    spans x from ``origin[0] + i * cell``, y from ``origin[1] + j * cell``."""

    storey: Storey
    origin: tuple[float, float]
    cell: float
    walls: BoolArray
    inside: BoolArray
    floor: BoolArray

    @property
    def free(self) -> BoolArray:
        return np.asarray(self.inside & self.floor & ~self.walls)

    @property
    def shape(self) -> tuple[int, int]:
        return (int(self.walls.shape[0]), int(self.walls.shape[1]))

    def centres(self, ij: NDArray[np.int64]) -> FloatArray:
        """``(K, 2)`` xy of the middles of cells ``ij``."""
        return np.asarray(self.origin) + (np.asarray(ij, dtype=float) + 0.5) * self.cell

    def cells(self, xy: FloatArray) -> NDArray[np.int64]:
        """``(K, 2)`` indices of the cells holding ``xy`` (perhaps off the grid)."""
        return np.floor((np.asarray(xy) - np.asarray(self.origin)) / self.cell).astype(np.int64)


def storey_plan(points: FloatArray, storey: Storey, cell: float, knee: float = KNEE,
                head: float = HEAD, normals: FloatArray | None = None) -> Plan:
    """The plan of ``storey`` in the ``(N, 3)`` cloud ``points``, on cells of ``cell`` m."""
    z = points[:, 2]
    top = min(storey.z + head, storey.ceiling - CEILING_MARGIN)
    in_storey = (z >= storey.z - FLOOR_BAND) & (z <= top)
    if not in_storey.any():
        raise ValueError(f"storey {storey.index} at {storey.z:g} m holds no points")
    xy = points[in_storey, :2]
    pad = math.ceil(OUTLINE_GAP / cell / 2) + 2
    origin = np.floor(xy.min(axis=0) / cell) * cell - pad * cell
    shape = tuple(int(n) for n in np.floor((xy.max(axis=0) - origin) / cell) + pad + 1)
    if shape[0] * shape[1] > MAX_CELLS:
        span = xy.max(axis=0) - xy.min(axis=0)
        raise ValueError(f"storey {storey.index} spans {span[0]:.0f} m x {span[1]:.0f} m: more "
                         f"than {MAX_CELLS:,} cells of {cell:g} m; crop the cloud to the "
                         "building (strays far from it?) or use larger cells")
    blank = np.zeros(shape, bool)
    grid = Plan(storey, (float(origin[0]), float(origin[1])), cell, blank, blank, blank)
    upright = (z >= storey.z + knee) & (z < top)
    if normals is not None:  # table tops and shelves are horizontal: never walls
        upright &= np.abs(np.asarray(normals)[:, 2]) < 0.5
    walls = _walls(grid, points[upright], storey.z + knee, top)
    floor = _floor(grid, points[np.abs(z - storey.z) <= FLOOR_BAND, :2], walls)
    inside = _inside(walls, cell)
    return Plan(storey, grid.origin, cell, walls, inside, floor)


def _walls(grid: Plan, slice_points: FloatArray, z0: float, z1: float) -> BoolArray:
    """Cells of tall structures (see the module's docstring)."""
    ij = grid.cells(slice_points[:, :2])
    flat = ij[:, 0] * grid.shape[1] + ij[:, 1]
    layer = np.clip(((slice_points[:, 2] - z0) / ((z1 - z0) / LAYERS)).astype(np.int64), 0,
                    LAYERS - 1)
    present = np.unique(flat * LAYERS + layer)
    bits = np.zeros(grid.shape[0] * grid.shape[1], dtype=np.uint8)
    np.bitwise_or.at(bits, present // LAYERS, (1 << (present % LAYERS)).astype(np.uint8))
    bits = bits.reshape(grid.shape)
    around = _or_around(bits, max(1, round(WALL_REACH / grid.cell)))
    counts = np.array([bin(b).count("1") for b in range(1 << LAYERS)])[around]
    high = (bits >> (LAYERS // 2)) > 0  # its own points reach the slice's upper half
    tall = high & (counts >= math.ceil(WALL_SHARE * LAYERS))
    side = _odd(GAP / grid.cell)
    tall = ndimage.binary_closing(tall, structure=np.ones((side, side), bool))
    blobs, n = ndimage.label(tall, structure=np.ones((3, 3), bool))
    if n:
        span = np.zeros(n + 1)
        for k, box in enumerate(ndimage.find_objects(blobs), start=1):
            if box is not None:
                span[k] = max(s.stop - s.start for s in box) * grid.cell
        tall &= span[blobs] >= MIN_BLOB
    return np.asarray(tall)


def _or_around(bits: NDArray[np.uint8], reach: int) -> NDArray[np.uint8]:
    """Each cell's bits or-ed with those of the cells up to ``reach`` cells away along x and
    y (a square)."""
    out = bits.copy()
    for axis in (0, 1):
        padded = np.pad(out, [(reach, reach) if a == axis else (0, 0) for a in (0, 1)])
        n = out.shape[axis]
        for shift in range(2 * reach + 1):
            out |= padded[shift:shift + n] if axis == 0 else padded[:, shift:shift + n]
    return out


def _floor(grid: Plan, xy: FloatArray, walls: BoolArray) -> BoolArray:
    """Cells near floor points; a wall's foot is no floor (walls go through every level)."""
    seen = np.zeros(grid.shape, bool)
    ij = grid.cells(xy)
    seen[ij[:, 0], ij[:, 1]] = True
    seen &= ~walls
    reach = max(round(FLOOR_REACH / grid.cell), 1)
    near = ndimage.distance_transform_edt(~seen) <= reach
    holes = ndimage.binary_fill_holes(near) & ~near
    labels, n = ndimage.label(holes)
    if n:
        sizes = np.bincount(labels.ravel(), minlength=n + 1) * grid.cell**2
        near |= (labels > 0) & (sizes[labels] < FLOOR_HOLE)
    return np.asarray(near)


def _inside(walls: BoolArray, cell: float) -> BoolArray:
    """What the walls enclose, openings up to ``OUTLINE_GAP`` closed."""
    size = _odd(OUTLINE_GAP / cell)
    closed = ndimage.minimum_filter(ndimage.maximum_filter(walls, size=size, mode="constant"),
                                    size=size, mode="constant", cval=True)
    return np.asarray(ndimage.binary_fill_holes(closed))


def _odd(cells: float) -> int:
    """The least odd number of cells spanning ``cells`` and one more: a square centred on a
    cell, so that a closing gives back the walls where they were."""
    return 2 * math.ceil(cells / 2) + 1


def surface_spacing(points: FloatArray) -> float:
    """The mean spacing (m) of ``points`` on the surfaces they sample: the side of the square
    each covers, from how many share each occupied ``PROBE`` voxel (a surface crosses about
    ``PROBE``² of each voxel it passes through)."""
    if len(points) < 2:
        return math.inf
    index = np.floor((points - points.min(axis=0)) / PROBE).astype(np.int64)
    span = index.max(axis=0) + 1
    keys = (index[:, 0] * span[1] + index[:, 1]) * span[2] + index[:, 2]
    return PROBE / math.sqrt(len(points) / len(np.unique(keys)))
