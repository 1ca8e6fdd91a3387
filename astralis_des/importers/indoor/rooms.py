"""A storey's free space cut into rooms, and what each room is.

Rooms meet at doors, and a door is narrow: every free cell's distance to the nearest wall
(scipy's Euclidean distance transform) is at most half a door's width in a doorway and more in
the middle of a room. So the cells farther than ``door_max / 2`` from any wall fall apart into
one piece per room (the erosion that parts rooms at their doors); a room narrower than
``door_max`` (a washroom, a narrow corridor) has no such piece, and gets the piece of its cells
farther than ``NARROW / 2`` when that piece holds none of the others (it is parted from them by
a door narrower than itself); and a watershed from those pieces over the distance, downhill
(scikit-image's), regrows each to its walls and up to the middle of its doorways. A passage
wider than ``door_max`` keeps both sides one room (an open-plan space, an L-shaped room). Free
parts no piece reached (a room narrower than a door) are rooms of their own when large enough;
pieces smaller than ``min_area`` join the neighbour they share most boundary with.

A room's kind: a **corridor** is long and narrow (its median width along its skeleton at most
``CORRIDOR_WIDTH``, its area at least ``ELONGATION`` squares of that width) with at least
``CORRIDOR_DOORS`` doors; a **hall** is any other room of ``HALL_AREA`` or more; the rest are
rooms.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from astralis_des.importers.indoor.plan import BoolArray, Plan

IntArray = NDArray[np.int64]
DOOR_MAX = 1.4  # m, the widest passage that still parts two rooms
MIN_DOOR = 0.4  # m, the narrowest: thinner free strips are dropped
NARROW = 1.1  # m: a room this wide or wider, narrower than ``DOOR_MAX``, is parted at its doors
MIN_AREA = 1.0  # m², the smallest room
CORRIDOR_WIDTH = 3.0  # m
ELONGATION = 3.0
CORRIDOR_DOORS = 3
HALL_AREA = 60.0  # m²


@dataclass(frozen=True)
class FoundRoom:
    """A room found on a storey: its floor's cells (``mask``, ``cell`` square, over its
    bounding box from ``lo`` to ``hi``), its outline as a polygon (xy, metres, along the
    cells' edges), area and kind."""

    id: str
    storey: int
    label: int  # its number in the storey's label grid
    kind: str  # room, corridor or hall (void: sealed, in ``Interior.voids``)
    area: float  # m²
    lo: tuple[float, float]  # bounding box
    hi: tuple[float, float]
    polygon: tuple[tuple[float, float], ...]
    mask: BoolArray
    cell: float

    @property
    def centre(self) -> tuple[float, float]:
        """The middle of its cells (perhaps outside an L-shaped room)."""
        i, j = np.nonzero(self.mask)
        return (self.lo[0] + (float(i.mean()) + 0.5) * self.cell,
                self.lo[1] + (float(j.mean()) + 0.5) * self.cell)


def segment(free: BoolArray, cell: float, door_max: float = DOOR_MAX,
            min_area: float = MIN_AREA) -> IntArray:
    """The rooms of the ``free`` cells: a label grid, 0 where no room is, rooms numbered from
    1 in the order of their first cell."""
    from skimage.morphology import disk
    from skimage.segmentation import relabel_sequential, watershed

    radius = max(1, round(MIN_DOOR / 2 / cell) - 1)
    free = ndimage.binary_opening(free, structure=disk(radius).astype(bool))
    distance = ndimage.distance_transform_edt(free) * cell
    markers, count = ndimage.label(distance > door_max / 2)
    narrow, more = ndimage.label(distance > NARROW / 2)  # rooms narrower than a wide door
    if more:
        alone = np.ones(more + 1, dtype=bool)
        alone[np.unique(narrow[markers > 0])] = False
        alone[0] = False
        extra, _ = ndimage.label(alone[narrow])
        markers = np.where(extra > 0, extra + count, markers)
        count = int(markers.max())
    labels = np.asarray(watershed(-distance, markers, mask=free), dtype=np.int64)
    rest, more = ndimage.label(free & (labels == 0))
    if more:
        index = np.arange(1, more + 1)
        size = ndimage.sum_labels(np.ones_like(rest), rest, index) * cell**2
        wide = 2 * ndimage.maximum(distance, rest, index) >= MIN_DOOR
        keep = np.zeros(more + 1, dtype=np.int64)
        keep[1:] = np.where((size >= min_area) & wide, index + count, 0)
        labels = np.where(labels > 0, labels, keep[rest])
    labels = _absorb_small(labels, cell, min_area)
    return np.asarray(relabel_sequential(labels)[0], dtype=np.int64)


def _absorb_small(labels: IntArray, cell: float, min_area: float) -> IntArray:
    """Rooms under ``min_area`` joined to the neighbour they touch most, or dropped."""
    sizes = np.bincount(labels.ravel()) * cell**2
    small = np.flatnonzero(sizes < min_area)
    small = small[(small > 0) & (sizes[small] > 0)]
    if not len(small):
        return labels
    target = np.arange(len(sizes))
    pairs = contacts(labels)
    for s in small:
        touching = [(n, b) for (a, b), n in pairs.items() if a == s and sizes[b] >= min_area]
        touching += [(n, a) for (a, b), n in pairs.items() if b == s and sizes[a] >= min_area]
        target[s] = max(touching)[1] if touching else 0
    return np.asarray(target[labels])


def contacts(labels: IntArray) -> dict[tuple[int, int], int]:
    """How many pairs of side-by-side cells each two rooms ``(a, b)``, ``a < b``, share."""
    out: dict[tuple[int, int], int] = {}
    for a, b in _neighbours(labels):
        touch = (a != b) & (a > 0) & (b > 0)
        lo, hi = np.minimum(a[touch], b[touch]), np.maximum(a[touch], b[touch])
        keys, counts = np.unique(np.stack([lo, hi]), axis=1, return_counts=True)
        for (p, q), n in zip(keys.T, counts, strict=True):
            out[(int(p), int(q))] = out.get((int(p), int(q)), 0) + int(n)
    return out


def _neighbours(grid: NDArray[np.int64]) -> list[tuple[IntArray, IntArray]]:
    """Each cell beside its neighbour along x, then along y."""
    return [(grid[:-1, :], grid[1:, :]), (grid[:, :-1], grid[:, 1:])]


def describe(plan: Plan, labels: IntArray, doors: dict[int, int]) -> list[FoundRoom]:
    """The rooms of a storey's ``labels``, each with its kind (``doors``: how many doors each
    label has), numbered ``storey.k`` from the south-west."""
    from skimage.measure import approximate_polygon, find_contours

    found = []
    boxes = ndimage.find_objects(labels)
    for label, box in enumerate(boxes, start=1):
        if box is None:
            continue
        mask = labels[box] == label
        origin = (round(plan.origin[0] + box[0].start * plan.cell, 3),
                  round(plan.origin[1] + box[1].start * plan.cell, 3))
        area = float(mask.sum()) * plan.cell**2
        outline = max(find_contours(np.pad(mask, 1).astype(float), 0.5), key=len)
        outline = approximate_polygon(outline, tolerance=1.0)[:-1]
        polygon = tuple((round(origin[0] + (float(r) - 0.5) * plan.cell, 3),
                         round(origin[1] + (float(c) - 0.5) * plan.cell, 3))
                        for r, c in outline)
        found.append(FoundRoom(
            "", plan.storey.index, label, _kind(mask, plan.cell, area, doors.get(label, 0)),
            round(area, 2), origin,
            (round(origin[0] + mask.shape[0] * plan.cell, 3),
             round(origin[1] + mask.shape[1] * plan.cell, 3)),
            polygon, mask, plan.cell))
    found.sort(key=lambda r: (round(r.lo[1], 1), round(r.lo[0], 1)))
    return [replace(r, id=f"{r.storey}.{k}") for k, r in enumerate(found, start=1)]


def _kind(mask: BoolArray, cell: float, area: float, doors: int) -> str:
    from skimage.morphology import skeletonize

    padded = np.pad(mask, 1)
    skeleton = skeletonize(padded)
    distance = ndimage.distance_transform_edt(padded)
    width = 2 * float(np.median(distance[skeleton])) * cell if skeleton.any() else 0.0
    if doors >= CORRIDOR_DOORS and 0 < width <= CORRIDOR_WIDTH and \
            area >= ELONGATION * width**2:
        return "corridor"
    return "hall" if area >= HALL_AREA else "room"
