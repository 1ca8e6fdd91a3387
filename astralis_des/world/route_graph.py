"""The graph routes are searched on (:class:`~astralis_des.world.routing.Router` builds it
once per world): a node for each room's centre, the inside and the wall of its door, corridor
stops, stair landings, flights, lift platforms and UAV wells, building entrances, the places of
a found interior (a visibility graph in each) and the corners round outdoor obstacles; an edge
carries its length for each kind that may take it."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from astralis_des.kinds import KIND_DEFAULTS, KINDS, KindDefaults
from astralis_des.world.geometry import FloatArray, segments_hit_boxes
from astralis_des.world.interior_routes import reflex_corners, side_of, visible
from astralis_des.world.parts import BLOCK, Building, InteriorPlan, Room, Solid, Space

OUTDOOR_MARGIN = 1.0  # how far outside a footprint corner the outdoor route turns
STAIR_RUN_FACTOR = 2.0  # horizontal run of a flight of stairs per metre of rise
UAV_WELL = 1.5  # m from the stairwell's far wall: where UAVs rise and sink between floors
DOORWAY = 0.6  # m: routes cross a door square to its wall, from this far inside the room
WALL_HALF = 0.15  # m: half a found wall (a door's centre is in its middle)
# Not outdoor blockers: walls and slabs are inside footprints, and an imported world's blocks
# (thousands) are left to the navigator, which flies or walks round them on a grid.
NOT_BLOCKERS = ("wall", "slab", BLOCK)


class Site(Protocol):
    """What routing needs of a world (:class:`~astralis_des.world.model.World` is one)."""

    @property
    def buildings(self) -> dict[str, Building]: ...
    @property
    def rooms(self) -> dict[str, Room]: ...
    @property
    def spaces(self) -> dict[str, Space]: ...
    @property
    def solids(self) -> tuple[Solid, ...]: ...
    @property
    def block_array(self) -> FloatArray: ...
    @property
    def areas(self) -> list[Room]: ...
    @property
    def stairs_passable_by(self) -> dict[str, tuple[str, ...]]: ...
    @property
    def interior(self) -> InteriorPlan | None: ...
    def contains(self, point: tuple[float, ...] | FloatArray) -> bool: ...
    def room_at(self, point: tuple[float, ...] | FloatArray) -> Room | None: ...


class GraphBuilder:
    """Builds a router's graph: its nodes (``names``, ``index``, positions) and edges."""

    world: Site
    names: list[str]
    index: dict[str, int]
    _pos: list[tuple[float, float, float]]
    _edges: list[tuple[int, int, dict[str, float]]]
    corridor_nodes: dict[str, list[int]]
    outdoor_nodes: list[int]
    place_nodes: dict[str, list[int]]
    _outlines: dict[str, FloatArray]
    _footprints: FloatArray

    def positions_of(self, nodes: list[int]) -> FloatArray:
        """``(N, 2)`` xy of ``nodes`` (while the graph is built too)."""
        return np.array([self._pos[n][:2] for n in nodes], dtype=float).reshape(-1, 2)

    def _node(self, name: str, pos: tuple[float, float, float]) -> int:
        self.index[name] = len(self.names)
        self.names.append(name)
        self._pos.append(pos)
        return self.index[name]

    def _edge(self, u: int, v: int, kinds: Sequence[str] = KINDS,
              length: float | None = None) -> None:
        d = length if length is not None else math.dist(self._pos[u], self._pos[v])
        self._edges.append((u, v, dict.fromkeys(kinds, d)))

    def _build(self) -> None:
        w = self.world
        for corr in (s for s in w.spaces.values() if s.kind == "corridor"):
            box = corr.box
            yc, z = (box.lo[1] + box.hi[1]) / 2, box.lo[2]
            rooms = [r for r in w.rooms.values() if r.corridor == corr.id]
            xs = sorted({box.lo[0] + 0.5, box.hi[0] - 0.75, *(r.door.center[0] for r in rooms)})
            nodes = [self._node(f"{corr.id}:{i}", (x, yc, z)) for i, x in enumerate(xs)]
            for u, v in itertools.pairwise(nodes):
                self._edge(u, v)
            self.corridor_nodes[corr.id] = nodes
            for room in rooms:
                door = self._node(f"{room.id}:door", room.door.center)
                inside = self._node(f"{room.id}:inside", room.door_point("room", DOORWAY))
                centre = self._node(room.id, room.center)
                self._edge(centre, inside)
                self._edge(inside, door)  # through the doorway square to the wall
                self._edge(door, nodes[xs.index(room.door.center[0])])
        for b in w.buildings.values():
            stair = w.spaces[f"{b.id}.stairwell"].box
            # the landing, between the lift's shaft and the corridor: where every kind enters
            west = b.lift.hi[0] if b.lift is not None else stair.lo[0]
            sx = (west + stair.hi[0]) / 2
            passable = w.stairs_passable_by.get(b.id, KINDS)
            previous = None
            for floor in range(1, b.floors + 1):
                corridor = self.corridor_nodes[f"{b.id}.{floor}.corridor"]
                z = (floor - 1) * b.floor_height
                yc = self._pos[corridor[0]][1]
                node = self._node(f"{b.id}.{floor}.stair", (sx, yc, z))
                self._edge(node, corridor[0])
                # the flights of stairs go south of the landing where there is room for them,
                # else north; UAVs change floors at the north end, clear of the lift and (off
                # the flights' line) of the walkers
                run = STAIR_RUN_FACTOR * b.floor_height / 2
                south = yc - run >= stair.lo[1] + 0.5
                if previous is not None:  # a UGV takes the lift where there is one
                    self._stairs(previous, node, (yc - run) if south else
                                 min(yc + run, stair.hi[1] - 0.5), tuple(
                        k for k in passable if _by_stairs(KIND_DEFAULTS[k], b)))
                lifted = tuple(k for k in passable if KIND_DEFAULTS[k].floors == "lift")
                if lifted and b.lift is not None:  # onto the lift's platform
                    lift = self._node(f"{b.id}.{floor}.lift", (*b.lift.center[:2], z))
                    self._edge(node, lift, lifted)
                    if floor > 1:
                        self._edge(self.index[f"{b.id}.{floor - 1}.lift"], lift, lifted)
                flown = tuple(k for k in passable if KIND_DEFAULTS[k].floors == "well")
                if flown:
                    wx = sx if south or b.lift is None else b.lift.center[0]
                    well = self._node(f"{b.id}.{floor}.well",
                                      (wx, max(stair.hi[1] - UAV_WELL, yc), z))
                    self._edge(node, well, flown)
                    if floor > 1:
                        self._edge(self.index[f"{b.id}.{floor - 1}.well"], well, flown)
                previous = node
            outside = self._node(f"{b.id}:entrance", b.entrance)
            self._edge(outside, self.corridor_nodes[f"{b.id}.1.corridor"][-1])
            self.outdoor_nodes.append(outside)
        self._interior()
        for area in w.areas:  # a room in the open: its door is an outdoor place
            door = self._node(f"{area.id}:door", area.door.center)
            inside = self._node(f"{area.id}:inside", area.door_point("room", DOORWAY))
            self._edge(self._node(area.id, area.center), inside)
            self._edge(inside, door)
            self.outdoor_nodes.append(door)
        inner = [w.interior.footprint] if w.interior is not None else []
        for solid in [b.footprint for b in w.buildings.values()] + inner + [
            s.box for s in w.solids if s.kind not in NOT_BLOCKERS
        ]:
            for cx in (solid.lo[0] - OUTDOOR_MARGIN, solid.hi[0] + OUTDOOR_MARGIN):
                for cy in (solid.lo[1] - OUTDOOR_MARGIN, solid.hi[1] + OUTDOOR_MARGIN):
                    if w.contains((cx, cy)):
                        name = f"corner:{len(self.outdoor_nodes)}"
                        self.outdoor_nodes.append(self._node(name, (cx, cy, 0.0)))
        pts = np.array([self._pos[i] for i in self.outdoor_nodes])
        for a in range(len(pts)):
            others = np.arange(a + 1, len(pts))
            clear = self._outdoor_clear(np.repeat(pts[a:a + 1], len(others), 0), pts[others])
            for b_idx in others[clear]:
                self._edge(self.outdoor_nodes[a], self.outdoor_nodes[b_idx])

    def _interior(self) -> None:
        """A found building's graph: each place's seat and the inside of each of its doors,
        joined to one another (the navigator walks round what is between them), each door's
        two sides through it, an entrance's outside to the outdoor places, and stairs from
        seat to seat, as long as their flights."""
        plan = self.world.interior
        if plan is None:
            return
        sides: dict[str, list[int]] = {p: [] for p in plan.seats}
        for k, opening in enumerate(plan.openings):
            door = opening.door
            centre = self._node(f"{plan.group}:door{k}", door.center)
            axis = door.normal_axis
            first = side_of(plan, opening.places[0], door, DOORWAY + WALL_HALF)
            for place in opening.places:  # the other place, or the outside, is across
                toward = first if place == opening.places[0] else -first
                point = list(door.center)
                point[axis] += toward * (DOORWAY + WALL_HALF)
                node = self._node(f"{plan.group}:door{k}:{place or 'outside'}",
                                  (point[0], point[1], point[2]))
                self._edge(node, centre)
                if place is None:
                    self.outdoor_nodes.append(node)
                else:
                    sides[place].append(node)
        for place, doors in sides.items():  # a visibility graph in each place
            outline = np.asarray(plan.outlines[place], dtype=float)
            z = plan.seats[place][2]
            corners = [self._node(f"{place}:corner{k}", (float(x), float(y), z))
                       for k, (x, y) in enumerate(reflex_corners(outline))]
            nodes = [self._node(place, plan.seats[place]), *doors, *corners]
            pairs = np.array(list(itertools.combinations(range(len(nodes)), 2))).reshape(-1, 2)
            xy = self.positions_of(nodes)
            seen = visible(xy[pairs[:, 0]], xy[pairs[:, 1]], outline)
            for i, j in pairs[seen]:
                self._edge(nodes[i], nodes[j])
            self.place_nodes[place] = nodes
            self._outlines[place] = outline
        for stair in plan.stairs:
            low, high = (self.index[p] for p in stair.places)
            rise = abs(self._pos[high][2] - self._pos[low][2])
            run = math.dist(self._pos[low][:2], self._pos[high][:2])
            self._edge(low, high, stair.kinds, run + STAIR_RUN_FACTOR * rise)

    def _stairs(self, lower: int, upper: int, y_mid: float, walkers: tuple[str, ...]) -> None:
        """Between two floors of a stairwell, from its landing (the stair node, by the
        corridor): ``walkers`` take a switchback flight to a mid-landing at ``y_mid`` (a run
        of twice the rise makes the route as long as the stairs). (The UGV rides the lift in
        its shaft west of the landing, UAVs rise in the open well at the north end:
        ``_build``.)"""
        x, _, z0 = self._pos[lower]
        rise = self._pos[upper][2] - z0
        if walkers:
            mid = self._node(f"{self.names[lower]}:flight", (x, y_mid, z0 + rise / 2))
            self._edge(lower, mid, walkers)
            self._edge(mid, upper, walkers)

    def _outdoor_blockers(self) -> FloatArray:
        boxes = [b.footprint for b in self.world.buildings.values()]
        if self.world.interior is not None:
            boxes.append(self.world.interior.footprint)
        boxes += [s.box for s in self.world.solids if s.kind not in NOT_BLOCKERS]
        return np.array([[[*b.lo[:2], -1.0], [*b.hi[:2], 1.0]] for b in boxes]).reshape(-1, 2, 3)

    def _outdoor_clear(self, p0: FloatArray, p1: FloatArray) -> np.ndarray:
        flat0 = np.column_stack([p0[:, :2], np.zeros(len(p0))])
        flat1 = np.column_stack([p1[:, :2], np.zeros(len(p1))])
        return ~segments_hit_boxes(flat0, flat1, self._footprints)


def _by_stairs(kind: KindDefaults, building: Building) -> bool:
    """Whether the kind takes the stairs of ``building`` (a lift-taker where it has none)."""
    return kind.floors == "stairs" or (kind.floors == "lift" and building.lift is None)
