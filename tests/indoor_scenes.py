"""Indoor point clouds with known storeys, rooms and doors, for ``tests/test_indoor_rooms.py``
and ``tools/bench/bench_indoor.py``.

A :class:`Scene` is a building as boxes (walls, slabs, furniture) with its truth: the storeys'
floor heights, each room's inner floor rectangles, each door's centre and width.
:func:`face_cloud` samples points at random on the boxes' faces, where a scan from inside would
see them: a face inside another box is hidden (a slab under a wall), and so is one out of reach
of the rooms, corridors and doorways (the outer faces of the outer walls, the roof's top, a
sealed void). Then a little Gaussian noise and a random share of the points dropped, as
occlusion would. (The 3-D lidar flown through a scene: ``tests/indoor_scan.py``.)

The scenes: building A of the default world (:func:`building_a`; any world file's building:
:func:`world_building`) and a generated building of irregular rooms (:func:`irregular`).
:func:`score` compares what :func:`astralis_des.importers.indoor.find_interior` found with a
scene's truth.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from astralis_des.importers.indoor import Interior, Plan
from astralis_des.world.build import load_world

ROOT = Path(__file__).resolve().parents[1]
WORLD_WALL = 0.2  # m, the world files' default wall_thickness (the shipped ones keep it)
Vec3 = tuple[float, float, float]
BoxT = tuple[Vec3, Vec3]
Rect = tuple[float, float, float, float]  # x0, y0, x1, y1


@dataclass(frozen=True)
class TrueRoom:
    id: str
    floor: float  # z of its floor
    rects: tuple[Rect, ...]  # its inner floor (inside the walls), a union of rectangles


@dataclass(frozen=True)
class TrueDoor:
    id: str
    centre: tuple[float, float]  # on the wall's middle line
    floor: float
    width: float  # the free gap
    normal_axis: int  # 0: the wall is normal to x (the line x = const), 1: normal to y
    entrance: bool = False


@dataclass
class Scene:
    name: str
    floors: list[float]  # z of each storey's floor
    storey_height: float  # floor to floor
    solids: list[BoxT] = field(default_factory=list)
    seen: list[BoxT] = field(default_factory=list)  # what a scan from inside reaches
    rooms: list[TrueRoom] = field(default_factory=list)
    spaces: list[TrueRoom] = field(default_factory=list)  # corridors, stairwells, lobbies
    doors: list[TrueDoor] = field(default_factory=list)
    furniture: int = 0  # how many of the solids are furniture


def face_cloud(scene: Scene, spacing: float, noise: float = 0.01, drop: float = 0.15,
               seed: int = 0) -> np.ndarray:
    """``(N, 3)`` points on the visible faces of ``scene``'s solids, one per ``spacing``²
    of face on average, moved by Gaussian ``noise`` (m), a share ``drop`` left out."""
    return oriented_cloud(scene, spacing, noise, drop, seed)[0]


def oriented_cloud(scene: Scene, spacing: float, noise: float = 0.01, drop: float = 0.15,
                   seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """:func:`face_cloud`'s points and their normals (each its face's, outwards)."""
    rng = np.random.default_rng(seed)
    solids = np.array(scene.solids, dtype=float)  # (K, 2, 3)
    seen = np.array(scene.seen, dtype=float)
    points, normals = [], []
    for k, (lo, hi) in enumerate(solids):
        for axis in range(3):
            u, v = [a for a in range(3) if a != axis]
            for at, sign in ((lo[axis], -1.0), (hi[axis], 1.0)):
                for (u0, u1), (v0, v1) in _tiles(lo, hi, u, v):
                    n = rng.poisson((u1 - u0) * (v1 - v0) / spacing**2)
                    if n == 0:
                        continue
                    p = np.empty((n, 3))
                    p[:, axis] = at
                    p[:, u] = rng.uniform(u0, u1, n)
                    p[:, v] = rng.uniform(v0, v1, n)
                    p = p[_visible(p, k, solids, seen)]
                    points.append(p)
                    normals.append(np.zeros_like(p))
                    normals[-1][:, axis] = sign
    xyz, nxyz = np.concatenate(points), np.concatenate(normals)
    kept = rng.random(len(xyz)) >= drop
    xyz, nxyz = xyz[kept], nxyz[kept]
    return xyz + rng.normal(0.0, noise, xyz.shape), nxyz


TILE = 2.0  # m: faces are sampled in patches this size, each checked against the boxes near it


def _tiles(lo: np.ndarray, hi: np.ndarray, u: int, v: int
           ) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    def cuts(a: float, b: float) -> list[tuple[float, float]]:
        edges = np.linspace(a, b, max(1, int(np.ceil((b - a) / TILE))) + 1)
        return list(zip(edges[:-1].tolist(), edges[1:].tolist(), strict=True))
    return [(cu, cv) for cu in cuts(lo[u], hi[u]) for cv in cuts(lo[v], hi[v])]


def _visible(p: np.ndarray, own: int, solids: np.ndarray, seen: np.ndarray) -> np.ndarray:
    """Not inside (or on) another solid, and on the boundary of a volume a scan reaches."""
    lo, hi = p.min(axis=0), p.max(axis=0)
    eps, reach = 1e-6, 0.01
    keep = np.ones(len(p), dtype=bool)
    near = np.all(solids[:, 0] <= hi + eps, axis=1) & np.all(solids[:, 1] >= lo - eps, axis=1)
    for j in np.flatnonzero(near):
        if j != own:
            keep &= ~np.all((p >= solids[j, 0] - eps) & (p <= solids[j, 1] + eps), axis=1)
    touched = np.zeros(len(p), dtype=bool)
    near = np.all(seen[:, 0] <= hi + reach, axis=1) & np.all(seen[:, 1] >= lo - reach, axis=1)
    for j in np.flatnonzero(near):
        touched |= np.all((p >= seen[j, 0] - reach) & (p <= seen[j, 1] + reach), axis=1)
    return keep & touched


def furnish(scene: Scene, rect: Rect, floor: float, rng: np.random.Generator) -> None:
    """A table (0.75 m), two chairs and a low cabinet (0.9 m) in the room ``rect``: clutter a
    plan must keep free."""
    x0, y0, x1, y1 = rect
    cx = rng.uniform(x0 + 1.2, x1 - 1.2)
    cy = rng.uniform(y0 + 1.2, y1 - 1.2)
    boxes = _table(cx, cy, floor)
    for dx in (-0.45, 0.45):
        boxes += _chair(cx + dx, cy - 0.75, floor)
    boxes.append(((x0, y1 - 0.45, floor), (x0 + 1.0, y1, floor + 0.9)))  # cabinet
    scene.solids += boxes
    scene.furniture += len(boxes)


def _table(cx: float, cy: float, z: float, sx: float = 1.4, sy: float = 0.8) -> list[BoxT]:
    top = ((cx - sx / 2, cy - sy / 2, z + 0.71), (cx + sx / 2, cy + sy / 2, z + 0.75))
    legs = [((x - 0.025, y - 0.025, z), (x + 0.025, y + 0.025, z + 0.71))
            for x in (cx - sx / 2 + 0.05, cx + sx / 2 - 0.05)
            for y in (cy - sy / 2 + 0.05, cy + sy / 2 - 0.05)]
    return [top, *legs]


def _chair(cx: float, cy: float, z: float) -> list[BoxT]:
    seat = ((cx - 0.22, cy - 0.22, z + 0.42), (cx + 0.22, cy + 0.22, z + 0.46))
    back = ((cx - 0.22, cy - 0.26, z + 0.46), (cx + 0.22, cy - 0.22, z + 0.95))
    legs = [((x - 0.015, y - 0.015, z), (x + 0.015, y + 0.015, z + 0.42))
            for x in (cx - 0.2, cx + 0.2) for y in (cy - 0.2, cy + 0.2)]
    return [seat, back, *legs]


def building_a(furnished: bool = True) -> Scene:
    """Building A of ``worlds/urban_default.yaml``: 3 storeys of 3.5 m, 18 rooms of 4 m x 7 m
    (walls included) on a corridor, a stairwell with the vehicle lift's shaft, a lobby and
    the entrance; a table, chairs and a cabinet in each room."""
    return world_building(ROOT / "worlds" / "urban_default.yaml", "A", furnished)


def world_building(path: Path, building_id: str, furnished: bool = True) -> Scene:
    """A building of a world file (built by ``astralis_des.world.build``, every wall
    ``WORLD_WALL`` thick), furnished like :func:`building_a`'s."""
    world = load_world(path)
    building = world.buildings[building_id]
    scene = Scene(building_id, [(f - 1) * building.floor_height
                                for f in range(1, building.floors + 1)],
                  building.floor_height)
    scene.solids = [(s.box.lo, s.box.hi) for s in world.solids
                    if s.label.split(" ")[0].split(".")[0] == building_id]
    rng = np.random.default_rng(7)
    for room in sorted(world.rooms.values(), key=lambda r: r.id):
        if room.building != building_id:
            continue
        lo, hi = room.box.lo, room.box.hi
        scene.rooms.append(TrueRoom(room.id, lo[2], ((lo[0], lo[1], hi[0], hi[1]),)))
        scene.seen.append((lo, hi))
        d = room.door
        scene.doors.append(TrueDoor(room.id, (d.center[0], d.center[1]), d.center[2], d.width,
                                    d.normal_axis))
        scene.seen.append(_doorway(d.center, d.normal_axis, d.width, d.height, WORLD_WALL))
        if furnished:
            furnish(scene, (lo[0], lo[1], hi[0], hi[1]), lo[2], rng)
    for space in world.spaces.values():
        if space.building == building_id:
            lo, hi = space.box.lo, space.box.hi
            scene.spaces.append(TrueRoom(space.id, lo[2], ((lo[0], lo[1], hi[0], hi[1]),)))
            scene.seen.append((lo, hi))
    # the entrance: in the east wall on the ground floor, min(1.6, corridor - 0.4) m wide
    # (world/build.py), its middle on the corridor's
    entrance = (building.footprint.hi[0], building.entrance[1], 0.0)
    scene.doors.append(TrueDoor(f"{building_id} entrance", entrance[:2], 0.0, 1.6, 0,
                                entrance=True))
    scene.seen.append(_doorway(entrance, 0, 1.6, 2.1, WORLD_WALL))
    return scene


def _doorway(centre: Vec3, axis: int, width: float, height: float, wall: float) -> BoxT:
    x, y, z = centre
    if axis == 0:
        return (x - wall / 2, y - width / 2, z), (x + wall / 2, y + width / 2, z + height)
    return (x - width / 2, y - wall / 2, z), (x + width / 2, y + wall / 2, z + height)


# -- the irregular building: 20 m x 14 m, two storeys of 3 m, floors at 12 m and 15 m ---------
T = 0.15  # wall thickness
SLAB = 0.25
DOOR_HEIGHT = 2.1
# (id, rectangles between wall middle lines); an L-shaped room is two rectangles, the second
# reaching a wall's thickness into the first (there is no wall between them)
PLAN: list[tuple[str, list[Rect]]] = [
    ("S1", [(0, 0, 5, 6)]),  # two doors: the corridor and S2
    ("S2", [(5, 0, 9, 6)]),  # two doors: the corridor and S1
    ("S3", [(9, 0, 14, 6)]),  # a sliding door half closed: a 0.6 m gap of 1.2
    ("L", [(0, 8, 8, 11), (0, 11 - T, 4, 14)]),  # L-shaped
    ("store", [(4, 11, 8, 14)]),  # onto the open-plan space
    ("open", [(8, 8, 20, 14), (14, 0, 20, 8 + T)]),  # open plan, L-shaped, with a partition
]                                                     # stub, a pillar and eight desks
DESKS = [(9.8, 9.6), (12.2, 9.6), (9.8, 12.4), (12.2, 12.4), (15.8, 9.6), (18.2, 9.6),
         (17.0, 2.5), (17.0, 5.0)]
CORRIDOR: list[Rect] = [(0, 6, 14, 8)]
# walls: (axis the wall is normal to, its line, from, to, [(door centre, gap)])
WALLS: list[tuple[int, float, float, float, list[tuple[float, float]]]] = [
    (1, 0, 0, 20, []), (1, 14, 0, 20, []), (0, 0, 0, 14, [(7, 1.2)]),  # west entrance
    (0, 20, 0, 14, [(3, 1.6)]),  # east entrance
    (1, 6, 0, 14, [(2.5, 0.9), (7, 0.9), (11.5, 1.2)]),
    (1, 8, 0, 14, [(6, 0.9)]),
    (0, 5, 0, 6, [(3, 0.8)]), (0, 9, 0, 6, []), (0, 14, 0, 8, [(7, 1.0)]),
    (0, 4, 11, 14, []), (1, 11, 4, 8, []), (0, 8, 8, 14, [(12.5, 0.8)]),
    (0, 14, 11.5, 14, []),  # the open plan's partition stub, 2.5 m
]
LEAF = (10.9, 11.5)  # x span of S3's half-closed sliding leaf, in its door's 10.9..12.1
ENTRANCES = {(0, 0.0), (0, 20.0)}  # (axis, line) of the walls whose gaps lead outside


def irregular(floors: tuple[float, ...] = (12.0, 15.0), furnished: bool = True) -> Scene:
    """Two storeys of one plan: a corridor, two rooms with two doors each, a room behind a
    half-closed sliding door, an L-shaped room, a store room and an L-shaped open-plan space
    with a partition stub, a pillar and desks; entrances at both ends on the lower storey."""
    height = floors[1] - floors[0] if len(floors) > 1 else 3.0
    scene = Scene("irregular", list(floors), height)
    rng = np.random.default_rng(11)
    for k, z in enumerate(floors, start=1):
        top = z + height - SLAB
        scene.solids.append(((0.0, 0.0, z - SLAB), (20.0, 14.0, z)))
        for axis, at, a, c, gaps in WALLS:
            outer = (axis, float(at)) in ENTRANCES
            gaps = gaps if (k == 1 or not outer) else []
            scene.solids += _wall(axis, at, a, c, gaps, z, top)
            for centre, gap in gaps:
                xyz = (centre, at, z) if axis == 1 else (at, centre, z)
                width = gap if (axis, at, centre) != (1, 6, 11.5) else LEAF[0] + gap - LEAF[1]
                mid = centre if width == gap else (LEAF[1] + LEAF[0] + gap) / 2
                door_xy = (mid, at) if axis == 1 else (at, mid)
                scene.doors.append(TrueDoor(f"{k}.{axis}.{at:g}.{centre:g}", door_xy, z, width,
                                            axis, entrance=outer))
                scene.seen.append(_doorway(xyz, axis, gap, DOOR_HEIGHT, T))
        scene.solids.append(((LEAF[0], 6 - 0.02, z), (LEAF[1], 6 + 0.02, z + DOOR_HEIGHT)))
        scene.solids.append(((16.8, 10.8, z), (17.2, 11.2, top)))  # the pillar
        for name, rects in PLAN:
            inner = tuple(_inner(r) for r in rects)
            scene.rooms.append(TrueRoom(f"{k}.{name}", z, inner))
            scene.seen += [((r[0], r[1], z), (r[2], r[3], top)) for r in inner]
        corridor = tuple(_inner(r) for r in CORRIDOR)
        scene.spaces.append(TrueRoom(f"{k}.corridor", z, corridor))
        scene.seen += [((r[0], r[1], z), (r[2], r[3], top)) for r in corridor]
        if furnished:
            for _, rects in PLAN[:4]:
                furnish(scene, _inner(rects[0]), z, rng)
            for x, y in DESKS:
                scene.solids += _table(x, y, z, 1.6, 0.8)
                scene.furniture += 5
    scene.solids.append(((0.0, 0.0, floors[-1] + height - SLAB),
                         (20.0, 14.0, floors[-1] + height)))  # the roof
    return scene


def _inner(r: Rect) -> Rect:
    """A rectangle between wall middle lines, less half a wall each side (the outer walls'
    too: every wall is ``T`` thick about its line)."""
    return (r[0] + T / 2, r[1] + T / 2, r[2] - T / 2, r[3] - T / 2)


def _wall(axis: int, at: float, a: float, c: float, gaps: list[tuple[float, float]],
          z0: float, z1: float) -> list[BoxT]:
    """The wall on the line ``coord[axis] == at`` from ``a`` to ``c``, with door gaps (and
    lintels over them)."""
    out: list[BoxT] = []
    start = a
    for lo, hi in [(g - w / 2, g + w / 2) for g, w in sorted(gaps)] + [(c, c)]:
        if lo > start:
            out.append(_wall_box(axis, at, start, lo, z0, z1))
        if hi > lo:
            out.append(_wall_box(axis, at, lo, hi, z0 + DOOR_HEIGHT, z1))
        start = hi
    return out


def _wall_box(axis: int, at: float, a: float, c: float, z0: float, z1: float) -> BoxT:
    if axis == 0:
        return (at - T / 2, a, z0), (at + T / 2, c, z1)
    return (a, at - T / 2, z0), (c, at + T / 2, z1)


# -- scoring what was found against the truth ------------------------------------------------
@dataclass
class Score:
    """How an :class:`Interior` compares with a scene's truth."""

    iou: dict[str, float]  # true room id -> best IoU of a found room on its storey
    matched: dict[str, str]  # true room id -> found room id (IoU >= 0.5)
    door_error: dict[str, tuple[float, float, bool]]  # true door -> (centre m, width m, axis ok)
    false_rooms: list[tuple[str, float]]  # found rooms over 4 m² that are no true room or space
    extra_doors: int  # found doors more than 0.5 m from every true door


def score(scene: Scene, interior: Interior) -> Score:
    """Rooms by IoU of their floor cells, doors by their centres' distance and widths'."""
    result = Score({}, {}, {}, [], 0)
    for storey, plan, labels in zip(interior.storeys, interior.plans, interior.labels,
                                    strict=True):
        truth = [r for r in scene.rooms if abs(r.floor - storey.z) < 0.3]
        spaces = [r for r in scene.spaces if abs(r.floor - storey.z) < 0.3]
        found = [r for r in interior.rooms if r.storey == storey.index]
        in_space = np.zeros(plan.shape, bool)
        for space in spaces:
            in_space |= _raster(plan, space.rects)
        truth_masks = {r.id: _raster(plan, r.rects) for r in truth}
        for room in truth:
            mask = truth_masks[room.id]
            best = (0.0, "")
            for f in found:
                mine = labels == f.label
                iou = float((mask & mine).sum() / max((mask | mine).sum(), 1))
                best = max(best, (iou, f.id))
            result.iou[room.id] = round(best[0], 3)
            if best[0] >= 0.5:
                result.matched[room.id] = best[1]
        for f in found:
            mine = labels == f.label
            if f.id in result.matched.values() or f.area <= 4.0:
                continue
            if (mine & in_space).sum() < 0.8 * mine.sum():
                result.false_rooms.append((f.id, f.area))
        doors = [d for d in scene.doors if abs(d.floor - storey.z) < 0.3]
        mine_doors = [d for d in interior.doors if d.storey == storey.index]
        for door in doors:
            if not mine_doors:
                result.door_error[door.id] = (np.inf, np.inf, False)
                continue
            dist = [float(np.hypot(d.centre[0] - door.centre[0], d.centre[1] - door.centre[1]))
                    for d in mine_doors]
            k = int(np.argmin(dist))
            near = mine_doors[k]
            result.door_error[door.id] = (round(dist[k], 3),
                                          round(abs(near.width - door.width), 3),
                                          near.normal_axis == door.normal_axis
                                          and near.entrance == door.entrance)
        for d in mine_doors:
            if all(np.hypot(d.centre[0] - t.centre[0], d.centre[1] - t.centre[1]) > 0.5
                   for t in doors):
                result.extra_doors += 1
    return result


def _raster(plan: Plan, rects: tuple[Rect, ...]) -> np.ndarray:
    """The plan's cells whose middles are in any of ``rects``."""
    x = plan.origin[0] + (np.arange(plan.shape[0]) + 0.5) * plan.cell
    y = plan.origin[1] + (np.arange(plan.shape[1]) + 0.5) * plan.cell
    out = np.zeros(plan.shape, bool)
    for x0, y0, x1, y1 in rects:
        out |= ((x >= x0) & (x < x1))[:, None] & ((y >= y0) & (y < y1))[None, :]
    return out
