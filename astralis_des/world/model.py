"""The world a mission runs in: buildings > floors > segments > rooms, and the outdoor site.

A :class:`World` is immutable once built and may be shared by many simulations.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from astralis_des.compiled import kernels
from astralis_des.memo import kept
from astralis_des.world.geometry import FloatArray, boxes_array, inside_polygon
from astralis_des.world.interior_routes import side_of
from astralis_des.world.parts import (
    BLOCK,
    Building,
    Door,
    InteriorPlan,
    Room,
    Segment,
    Solid,
    Space,
)
from astralis_des.world.routing import Router

if TYPE_CHECKING:
    from astralis_des.world.imported import Imported

MAP_RESOLUTION = 0.2  # m, the planner's voxels in a world of boxes
ENTRANCE_STEP = 1.5  # m outside an interior's entrance door: its entrance point
__all__ = ["BLOCK", "MAP_RESOLUTION", "Building", "Door", "Room", "Segment", "Solid", "Space",
           "World"]


@dataclass(frozen=True)
class World:
    name: str
    site: tuple[float, float]
    buildings: dict[str, Building]
    segments: dict[str, Segment]
    rooms: dict[str, Room]
    spaces: dict[str, Space]
    solids: tuple[Solid, ...]
    stairs_passable_by: dict[str, tuple[str, ...]] = field(default_factory=dict)
    surfaces: tuple[Solid, ...] = ()  # roads and such: drawn, walked on, never in the way
    imported: Imported | None = None  # a digital twin's mesh, cloud and source
    origin: tuple[float, float, float] | None = None  # (0, 0, 0): latitude, longitude, alt
    interior: InteriorPlan | None = None  # a building found in a scan or model

    def memo(self, name: str, limit: int) -> dict[Any, Any]:
        """A cache kept on the world for answers that depend on it and their key alone: it
        lasts as long as the world (a study's variants, a tune's trials reuse it), emptied when
        it reaches ``limit`` entries."""
        return kept(self, name, limit)

    @property
    def map_resolution(self) -> float:
        """The planner's voxel: an imported world's own, else ``MAP_RESOLUTION``."""
        return self.imported.voxel if self.imported is not None else MAP_RESOLUTION

    @cached_property
    def groups(self) -> set[str]:
        """What a mission may search by name: buildings and groups of areas."""
        return {*self.buildings, *(s.building for s in self.segments.values())}

    @cached_property
    def indoors(self) -> frozenset[str]:
        """The buildings' ids and the interior's group: the rooms of what has walls."""
        return frozenset([*self.buildings, *([self.interior.group] if self.interior else [])])

    @cached_property
    def entrances(self) -> dict[str, tuple[float, float, float]]:
        """Just outside each building's (and the interior's first) entrance, at ground level:
        where outdoor starts are drawn round and spots are listed from."""
        out = {bid: b.entrance for bid, b in self.buildings.items()}
        inner = self.interior
        ways = [o for o in inner.openings if o.places[1] is None] if inner is not None else []
        if inner is not None and ways:
            door = ways[0].door
            point = list(door.center)
            point[door.normal_axis] -= side_of(inner, ways[0].places[0], door, ENTRANCE_STEP) \
                * ENTRANCE_STEP  # across from the place inside
            out[inner.group] = (point[0], point[1], point[2])
        return out

    @cached_property
    def areas(self) -> list[Room]:
        """The search areas (rooms out in the open, not in a building)."""
        return [r for r in self.rooms.values() if r.building not in self.indoors]

    @cached_property
    def block_array(self) -> FloatArray:
        """``(K, 2, 3)`` corners of the imported blocks (a subset of ``solid_array``)."""
        return boxes_array([s.box for s in self.solids if s.kind == BLOCK])

    @cached_property
    def solid_array(self) -> FloatArray:
        """``(K, 2, 3)`` corners of every solid, for vectorised line-of-sight tests."""
        return boxes_array([s.box for s in self.solids])

    @cached_property
    def doorways(self) -> FloatArray:
        """``(N, 4)``: the centre (at floor height) of each opening in a wall that a robot
        passes through (each room's door, each building's entrance) and the axis its wall is
        normal to (0: x, 1: y)."""
        doors = [(*r.door.center, r.door.normal_axis) for r in self.rooms.values()
                 if r.building in self.buildings]
        doors += [(b.footprint.hi[0], b.entrance[1], b.footprint.lo[2], 0)
                  for b in self.buildings.values()]
        if self.interior is not None:
            doors += [(*o.door.center, o.door.normal_axis) for o in self.interior.openings]
        return np.array(doors, dtype=float).reshape(-1, 4)

    def near_doorway(self, points: FloatArray, floor: float, within: float) -> np.ndarray:
        """``(N,)``: where a point is within ``within`` (in the plane) of a doorway of the
        storey at ``floor``."""
        pts = np.atleast_2d(points)
        near = np.zeros(len(pts), dtype=bool)
        doors = self.doorways
        for door in doors[np.abs(doors[:, 2] - floor) < 1.0]:
            dx, dy = pts[:, 0] - door[0], pts[:, 1] - door[1]
            near |= np.sqrt(dx * dx + dy * dy) < within
        return near

    @cached_property
    def router(self) -> Router:
        return Router(self)

    def floor_below(self, point: tuple[float, ...] | FloatArray) -> float:
        """Height of the floor under ``point``: a storey's level inside a building or an
        interior, an area's floor inside an area (the highest at or below the point), else
        0."""
        x, y, z = float(point[0]), float(point[1]), float(point[2])
        inner = self.interior
        if inner is not None and inner.footprint.contains((x, y, inner.footprint.lo[2])):
            return max((f for f in inner.storeys if f <= z + 0.1), default=inner.storeys[0])
        for b in self.buildings.values():
            lo, hi = b.footprint.lo, b.footprint.hi
            if lo[0] <= x <= hi[0] and lo[1] <= y <= hi[1]:
                storey = min(max(int((z + 0.1) // b.floor_height), 0), b.floors - 1)
                return storey * b.floor_height
        floors = [a.box.lo[2] for a in self.areas
                  if a.box.lo[0] <= x <= a.box.hi[0] and a.box.lo[1] <= y <= a.box.hi[1]
                  and a.box.lo[2] <= z + 0.1]
        return max(floors, default=0.0)

    def floors_below(self, points: FloatArray) -> FloatArray:
        """:meth:`floor_below` of each of ``points`` (``(N, 3)``), the same values at once."""
        pts = np.asarray(points, dtype=float).reshape(-1, 3)
        x, y, z = pts[:, 0], pts[:, 1], pts[:, 2]
        out = np.zeros(len(pts))
        todo = np.ones(len(pts), dtype=bool)
        inner = self.interior
        if inner is not None:
            lo, hi = inner.footprint.lo, inner.footprint.hi
            hit = (lo[0] <= x) & (x <= hi[0]) & (lo[1] <= y) & (y <= hi[1])
            if hit.any():
                out[hit] = [self.floor_below(p) for p in pts[hit]]
            todo &= ~hit
        for b in self.buildings.values():
            lo, hi = b.footprint.lo, b.footprint.hi
            hit = todo & (lo[0] <= x) & (x <= hi[0]) & (lo[1] <= y) & (y <= hi[1])
            storey = np.clip(((z[hit] + 0.1) // b.floor_height).astype(int), 0, b.floors - 1)
            out[hit] = storey * b.floor_height
            todo &= ~hit
        area_floor = np.full(len(pts), -np.inf)
        for a in self.areas:
            (x0, y0, z0), (x1, y1, _) = a.box.lo, a.box.hi
            hit = todo & (x0 <= x) & (x <= x1) & (y0 <= y) & (y <= y1) & (z0 <= z + 0.1)
            area_floor[hit] = np.maximum(area_floor[hit], z0)
        out[todo] = np.where(np.isfinite(area_floor[todo]), area_floor[todo], 0.0)
        return out

    def on_floor(self, point: tuple[float, ...] | FloatArray) -> FloatArray:
        """``point`` brought down to the floor under it: where a robot stands, or the floor a
        UAV flies over (routes are asked between such points)."""
        here = np.array(point, dtype=float)
        here[2] = self.floor_below(here)
        return here

    def contains(self, point: tuple[float, ...] | FloatArray) -> bool:
        x, y = float(point[0]), float(point[1])
        return 0.0 <= x <= self.site[0] and 0.0 <= y <= self.site[1]

    @cached_property
    def room_ids(self) -> list[str]:
        return list(self.rooms)

    @cached_property
    def room_boxes(self) -> FloatArray:
        """``(R, 2, 3)`` corners of the rooms, in ``room_ids`` order."""
        return boxes_array([self.rooms[r].box for r in self.room_ids])

    @cached_property
    def room_bounds(self) -> tuple[FloatArray, FloatArray]:
        """The rooms' corners widened by 1e-6 (:meth:`room_at`'s tolerance)."""
        return self.room_boxes[:, 0] - 1e-6, self.room_boxes[:, 1] + 1e-6

    def room_at(self, point: tuple[float, ...] | FloatArray) -> Room | None:
        p = np.asarray(point, dtype=float)
        lo, hi = self.room_bounds
        compiled = kernels()
        if compiled is not None and p.shape == (3,):  # the same rooms, one by one
            inside = compiled.within(p[None], lo, hi, 3)[0]
        else:
            inside = np.all((p >= lo) & (p <= hi), axis=1)
        for k in np.flatnonzero(inside):  # a room that is no box: in its outline
            room = self.rooms[self.room_ids[k]]
            if not room.outline or inside_polygon(p[None, :2], room.outline)[0]:
                return room
        return None

    def rooms_holding(self, points: FloatArray) -> np.ndarray:
        """Indices into :attr:`room_ids`, in order, of the rooms (their boxes, faces included)
        any of ``points`` lies in."""
        ends = np.atleast_2d(points)
        boxes = self.room_boxes
        compiled = kernels()
        if compiled is not None and ends.shape[1] == 3 and ends.dtype == float:  # the same
            return np.flatnonzero(compiled.within(ends, boxes[:, 0], boxes[:, 1], 3)
                                  .any(axis=0))  # rooms, pair by pair
        near = np.flatnonzero(np.all((boxes[:, 0] <= ends.max(axis=0)) &
                                     (boxes[:, 1] >= ends.min(axis=0)), axis=1))
        if len(near) == 0:
            return near
        # the near rooms at once (ends x rooms x axes): the same rooms, one call each
        lo, hi = boxes[near, 0], boxes[near, 1]
        held = ((ends[:, None, :] >= lo[None]) & (ends[:, None, :] <= hi[None])).all(axis=2)
        return near[held.any(axis=0)]

    def line_of_sight(self, p0: FloatArray, p1: FloatArray) -> np.ndarray:
        """``(M,)`` mask, true where the segment ``p0[m] -> p1[m]`` meets no solid."""
        from astralis_des.world.geometry import segments_hit_boxes

        return ~segments_hit_boxes(p0, p1, self.solid_array)

    @property
    def area(self) -> float:
        return self.site[0] * self.site[1]

    def segment_order(self, building: str | None = None) -> list[str]:
        """Segments in id order (floor by floor), optionally of one building."""
        ids = [s for s, seg in self.segments.items() if building in (None, seg.building)]
        return sorted(ids, key=_natural_key)


def _natural_key(text: str) -> list[object]:
    return [int(p) if p.isdigit() else p for p in text.split(".")]
