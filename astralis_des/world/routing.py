"""Routes through the world for the kinematic fidelity: a graph of rooms, doors, corridors,
stairwells, entrances and outdoor corners, one per agent kind, searched from a node when a
route first leaves it (Dijkstra), its distances and predecessors kept for the next route.

An all-pairs matrix (issue 38) cost 0.5 GB at 1,000 rooms, 9.5 GB a kind at 10,000; only
the rows routes leave from are searched (the same rows), so routes are the same.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from astralis_des.errors import InputError
from astralis_des.kinds import KINDS
from astralis_des.memo import kept
from astralis_des.world.geometry import FloatArray, boxes_array
from astralis_des.world.interior_routes import visible
from astralis_des.world.route_graph import GraphBuilder, Site

SNAP = 0.5  # m: a point this close to a room or corridor (in a wall, by a door) belongs to it
CACHE_BYTES = 256_000_000  # of searched rows kept (12 B a node each): every row of a world of
# 1,000 rooms, 600 of one of 10,000
ROUTES_KEPT = 8192  # routes kept (a few waypoints each), and places of points


class Router(GraphBuilder):
    """Shortest routes between arbitrary points, for each agent kind."""

    def __init__(self, world: Site) -> None:
        self.world = world
        self.names: list[str] = []
        self.index: dict[str, int] = {}
        self._pos: list[tuple[float, float, float]] = []
        self._edges: list[tuple[int, int, dict[str, float]]] = []
        self.corridor_nodes: dict[str, list[int]] = {}
        self.outdoor_nodes: list[int] = []
        self.place_nodes: dict[str, list[int]] = {}  # an interior's places: their nodes
        self._outlines: dict[str, FloatArray] = {}  # and their floors' outlines
        self._reach: dict[tuple[str, str, str], bool] = {}
        self._space_ids = list(world.spaces)
        self._space_boxes = boxes_array([s.box for s in world.spaces.values()])
        self._footprints = self._outdoor_blockers()
        self._snap_ids = [*world.rooms, *world.spaces]
        self._snap_boxes = boxes_array([r.box for r in world.rooms.values()] +
                                       [s.box for s in world.spaces.values()])
        self._build()
        self.positions = np.array(self._pos, dtype=float)
        self._graphs = {kind: self._graph(kind) for kind in KINDS}
        self._rows: OrderedDict[tuple[str, int], tuple[FloatArray, np.ndarray]] = OrderedDict()
        self._row_limit = max(16, CACHE_BYTES // (12 * max(len(self.names), 1)))

    def _graph(self, kind: str) -> csr_matrix:
        rows: list[int] = []
        cols: list[int] = []
        vals: list[float] = []
        for u, v, lengths in self._edges:
            if kind in lengths:
                rows += [u, v]
                cols += [v, u]
                vals += [lengths[kind]] * 2
        n = len(self.names)
        return csr_matrix((vals, (rows, cols)), shape=(n, n))

    def graph(self, kind: str) -> csr_matrix:
        """The graph a ``kind`` moves on: node to node, each edge both ways (summed where an
        edge was added twice), as routes are searched on it."""
        return self._graphs[kind]

    def _from(self, kind: str, sources: list[int]) -> tuple[FloatArray, np.ndarray]:
        """``(len(sources), N)`` distances and predecessors from each source node, each row
        searched once and kept (the least recently used dropped past ``CACHE_BYTES``)."""
        missing = [u for u in dict.fromkeys(sources) if (kind, u) not in self._rows]
        if missing:
            dist, pred = dijkstra(self._graphs[kind], directed=False, indices=missing,
                                  return_predecessors=True)
            for k, u in enumerate(missing):
                self._rows[(kind, u)] = (dist[k], pred[k])
        for u in sources:
            self._rows.move_to_end((kind, u))
        found = [self._rows[(kind, u)] for u in sources]
        while len(self._rows) > self._row_limit:
            self._rows.popitem(last=False)
        return np.array([d for d, _ in found]), np.array([p for _, p in found])

    # -- queries --------------------------------------------------------------------------
    def place_of(self, point: FloatArray | tuple[float, ...]) -> str:
        """Name of the convex place holding ``point``: a room id, a space id or ``outdoor``
        (kept per point; a point in a wall or off the site is an ``InputError``)."""
        p = np.asarray(point, dtype=float)
        places: dict[tuple[Any, ...], str] = kept(self, "places", ROUTES_KEPT)
        key = (p.shape, p.tobytes())
        if key not in places:
            places[key] = self._place_of(p)
        return places[key]

    def _place_of(self, p: FloatArray) -> str:
        room = self.world.room_at(p)
        if room is not None:
            return room.id
        inside = np.all((p >= self._space_boxes[:, 0] - 0.05) &
                        (p <= self._space_boxes[:, 1] + 0.05), axis=1)
        if inside.any():
            return self._space_ids[int(np.argmax(inside))]
        near = self._nearest_space(p)
        if near is not None:  # in a wall's thickness, by a doorway: a body's centre can be
            return near
        where = "[" + ", ".join(f"{v:g}" for v in np.round(p, 2)) + "]"
        if not self.world.contains(p):
            raise InputError(f"point {where} is outside the world")
        if not self._outdoor_clear(p[None, :], p[None, :])[0]:
            raise InputError(f"point {where} is inside a building or obstacle")
        blocks = self.world.block_array
        if len(blocks) and np.all((p >= blocks[:, 0]) & (p < blocks[:, 1]), axis=1).any():
            raise InputError(f"point {where} is inside a block of the imported world")
        return "outdoor"

    def _nearest_space(self, p: FloatArray) -> str | None:
        """The room or space within ``SNAP`` of ``p`` (horizontally, on its level), if any."""
        boxes = self._snap_boxes
        if not len(boxes):
            return None
        gap = np.maximum(np.maximum(boxes[:, 0] - p, p - boxes[:, 1]), 0.0)
        d = np.sqrt(np.einsum("ij,ij->i", gap, gap))
        d[gap[:, 2] > SNAP] = np.inf
        best = int(np.argmin(d))  # the first of the nearest, as a scan in order would keep
        return self._snap_ids[best] if d[best] < SNAP else None

    def _entries(self, p: FloatArray, place: str) -> list[int]:
        if place in self.place_nodes:  # the nodes of an interior's place in sight of p
            nodes = self.place_nodes[place]
            xy = self.positions_of(nodes)
            seen = visible(np.repeat(p[None, :2], len(nodes), 0), xy, self._outlines[place])
            return [n for n, ok in zip(nodes, seen, strict=True) if ok] or nodes
        if place in self.world.rooms:
            return [self.index[place], self.index[f"{place}:inside"]]
        if place in self.corridor_nodes:
            return self.corridor_nodes[place]
        if place.endswith(".stairwell"):
            b = self.world.buildings[place.split(".")[0]]
            floor = min(b.floors, max(1, int(p[2] // b.floor_height) + 1))
            on_lift = f"{b.id}.{floor}.lift"
            stair = [self.index[f"{b.id}.{floor}.stair"]]
            if b.lift is not None and on_lift in self.index and b.lift.contains(p):
                return [self.index[on_lift], *stair]  # on the platform
            return stair
        outdoor = np.array(self.outdoor_nodes)
        pts = self.positions[outdoor]
        clear = self._outdoor_clear(np.repeat(p[None, :], len(pts), 0), pts)
        return [int(n) for n in outdoor[clear]]

    def reachable(self, start: FloatArray | tuple[float, ...], room_id: str, kind: str) -> bool:
        """Can a ``kind`` get from ``start`` to the room? It depends only on the place ``start``
        is in (any point of a room, corridor or the outdoors connects alike): cached."""
        return self.reachable_rooms(start, [room_id], kind)[0]

    def reachable_rooms(self, start: FloatArray | tuple[float, ...], room_ids: list[str],
                        kind: str) -> list[bool]:
        """:meth:`reachable` for several rooms (the place of ``start`` found once)."""
        place = self.place_of(start)
        out = []
        for room_id in room_ids:
            key = (kind, place, room_id)
            if key not in self._reach:
                door = self.world.rooms[room_id].door_point("corridor")
                self._reach[key] = self.route(start, door, kind) is not None
            out.append(self._reach[key])
        return out

    def route(self, start: FloatArray | tuple[float, ...], goal: FloatArray | tuple[float, ...],
              kind: str) -> FloatArray | None:
        """Waypoints from ``start`` to ``goal`` at floor level, or ``None`` if unreachable;
        read-only, kept per ends and kind (the world does not change), up to ``ROUTES_KEPT``."""
        p, q = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
        routes: dict[tuple[Any, ...], FloatArray | None] = kept(self, "routes", ROUTES_KEPT)
        key = (kind, p.shape, p.tobytes(), q.shape, q.tobytes())
        if key not in routes:
            routes[key] = _read_only(self._route(p, q, kind))
        return routes[key]

    def _route(self, p: FloatArray, q: FloatArray, kind: str) -> FloatArray | None:
        p_place, q_place = self.place_of(p), self.place_of(q)
        if p_place == q_place and (p_place != "outdoor" or self._outdoor_clear(
                p[None, :], q[None, :])[0]) and (p_place not in self._outlines or visible(
                    p[None, :2], q[None, :2], self._outlines[p_place])[0]):
            return np.array([p, q])
        a = self._entries(p, p_place)
        b = self._entries(q, q_place)
        if not a or not b:
            return None
        da = np.linalg.norm(self.positions[a] - p, axis=1)
        db = np.linalg.norm(self.positions[b] - q, axis=1)
        dist, pred = self._from(kind, a)
        total = da[:, None] + dist[:, b] + db[None, :]
        i, j = np.unravel_index(int(np.argmin(total)), total.shape)
        if not np.isfinite(total[i, j]):
            return None
        nodes = [b[j]]  # walked back from the goal's entry to the start's
        while nodes[-1] != a[i]:
            nodes.append(int(pred[i][nodes[-1]]))
        return np.vstack([p, self.positions[nodes[::-1]], q])


def _read_only(way: FloatArray | None) -> FloatArray | None:
    if way is not None:
        way.flags.writeable = False
    return way
