"""An indoor cloud's interior: storeys, the walls' heading, then for each storey its plan,
rooms and doors.

Plans are drawn along the walls: the cloud is turned by minus the walls' heading (found by
:func:`.heading.wall_heading` unless given) about the origin, and everything found (plans,
rooms' cells, polygons and boxes, doors' centres and axes) is in that turned frame, the
plan's; :meth:`Interior.to_cloud` turns plan coordinates back into the cloud's.

A space no door leads into, on a storey where doors join the others, is sealed: no room but a
**void** (:attr:`Interior.voids`). A scan never sees inside one, but a modelled building's
mesh shows every face, those of its sealed spaces too (building A of the default world has
one at each end of its corridor's far side, between its last rooms and its east wall), and
its floor, walls and ceiling look like a room's. A storey without any door keeps its spaces
as rooms (one room scanned, its door shut).
"""

from __future__ import annotations

import logging
from collections import Counter
from dataclasses import dataclass, replace

import numpy as np

from astralis_des.importers.indoor.doors import FoundDoor, find_doors
from astralis_des.importers.indoor.heading import turned, wall_heading
from astralis_des.importers.indoor.plan import HEAD, KNEE, Plan, storey_plan, surface_spacing
from astralis_des.importers.indoor.rooms import DOOR_MAX, FoundRoom, IntArray, describe, segment
from astralis_des.importers.indoor.storeys import Storey, find_storeys
from astralis_des.world.geometry import FloatArray

log = logging.getLogger(__name__)
CELL = 0.05  # m, the plans' cells, for a cloud at least as dense as ``DENSE``
DENSE = 0.12  # m between points on a surface; sparser clouds get cells of 2 * CELL
SPARSE = 0.15  # m: sparser still, walls have holes that rooms leak through


@dataclass(frozen=True)
class Interior:
    """What :func:`find_interior` found: the storeys (lowest first), each one's plan and room
    labels, the rooms and the doors."""

    cell: float  # m, the plans' cells
    spacing: float  # m, the points' mean spacing on the surfaces
    heading: float  # radians from the cloud's x axis to the plan's (along the walls)
    storeys: tuple[Storey, ...]
    plans: tuple[Plan, ...]
    labels: tuple[IntArray, ...]  # per storey: each free cell's room or void label, else 0
    rooms: tuple[FoundRoom, ...]
    doors: tuple[FoundDoor, ...]
    voids: tuple[FoundRoom, ...] = ()  # sealed spaces (kind "void", ids ``storey.vK``)

    def doors_of(self, room: str) -> list[FoundDoor]:
        return [d for d in self.doors if room in d.rooms]

    @property
    def entrances(self) -> list[FoundDoor]:
        return [d for d in self.doors if d.entrance]

    def to_cloud(self, xy: FloatArray) -> FloatArray:
        """``(N, 2)`` plan coordinates in the cloud's frame."""
        return turned(np.atleast_2d(np.asarray(xy, dtype=float)), self.heading)


def walls_heading(points: FloatArray, storeys: list[Storey] | tuple[Storey, ...],
                  knee: float = KNEE, head: float = HEAD) -> float:
    """Which way the walls of ``points`` run (radians, :func:`.heading.wall_heading`): of the
    points between knee and head height over each of ``storeys``' floors."""
    z = points[:, 2]
    walls = np.zeros(len(points), dtype=bool)
    for storey in storeys:
        walls |= (z >= storey.z + knee) & (z <= storey.z + head)
    return wall_heading(points[walls, :2])


def find_interior(points: FloatArray, *, normals: FloatArray | None = None,
                  cell: float | None = None, heading: float | None = None,
                  knee: float = KNEE, head: float = HEAD,
                  door_max: float = DOOR_MAX) -> Interior:
    """Storeys, rooms and doors of an ``(N, 3)`` indoor cloud (metres, z up; ``normals``
    optional, ``(N, 3)``), on plans of ``cell`` m (by default ``CELL``, or twice that for a
    cloud sparser than ``DENSE``) along walls at ``heading`` (radians; found when None):
    walls are what fills ``knee`` to ``head`` over each floor; passages up to ``door_max``
    wide part rooms."""
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points must be an (N, 3) array, not {points.shape}")
    if normals is not None and np.shape(normals) != points.shape:
        raise ValueError(f"normals must be shaped like the points {points.shape}, "
                         f"not {np.shape(normals)}")
    spacing = surface_spacing(points)
    if cell is None:
        cell = CELL if spacing <= DENSE else 2 * CELL
    if spacing > SPARSE:
        log.warning("the cloud's points are %.2f m apart on its surfaces: sparser than %g m, "
                    "walls have gaps that rooms may leak through", spacing, SPARSE)
    storeys = find_storeys(points, normals)
    if heading is None:
        heading = walls_heading(points, storeys, knee, head)
    points = turned(points, -heading)
    if normals is not None:
        normals = turned(np.asarray(normals, dtype=float), -heading)
    plans, grids, rooms, doors, voids = [], [], [], [], []
    for storey in storeys:
        plan = storey_plan(points, storey, cell, knee, head, normals)
        labels = segment(plan.free, cell, door_max)
        found = find_doors(plan, labels, {k: str(k) for k in range(1, int(labels.max()) + 1)})
        count = Counter(int(r) for d in found for r in d.rooms if r is not None)
        storey_rooms, sealed = _sealed_apart(describe(plan, labels, dict(count)), count)
        voids += sealed
        ids = {str(r.label): r.id for r in storey_rooms}
        doors += [replace(d, rooms=(ids.get(d.rooms[0] or ""), ids.get(d.rooms[1] or "")))
                  for d in found]
        plans.append(plan)
        grids.append(labels)
        rooms += storey_rooms
    return Interior(cell, round(spacing, 4), heading, tuple(storeys), tuple(plans),
                    tuple(grids), tuple(rooms), tuple(doors), tuple(voids))


def _sealed_apart(found: list[FoundRoom], doors: Counter[int]
                  ) -> tuple[list[FoundRoom], list[FoundRoom]]:
    """A storey's rooms with doors and its voids (see the module's docstring), each numbered
    anew in :func:`.rooms.describe`'s order: ``storey.k`` and ``storey.vK``."""
    if not doors:
        return found, []
    rooms = [r for r in found if doors[r.label]]
    voids = [r for r in found if not doors[r.label]]
    if voids:
        log.info("storey %d: %d sealed space(s) no door leads into, set apart as voids",
                 found[0].storey, len(voids))
    return ([replace(r, id=f"{r.storey}.{k}") for k, r in enumerate(rooms, start=1)],
            [replace(r, id=f"{r.storey}.v{k}", kind="void") for k, r in enumerate(voids, start=1)])
