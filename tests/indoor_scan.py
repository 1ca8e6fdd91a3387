"""Realistic indoor clouds of the buildings of ``tests/indoor_scenes.py``, for
``tests/test_indoor_scan.py``: a flight of the 3-D lidar through a scene, and the scene as a
mesh.

:func:`flight` derives the sensor's stops from a scene's truth, not per scene: on each storey
it comes in through the entrance (or up the stairwell), flies the lanes of every corridor,
stairwell and room (``LANE`` apart, a stop every ``STEP`` or less, ``FLIGHT`` over the floor,
``MARGIN`` off the walls) and goes from one to the next through the doors that join them (a
stop in each doorway) or the openings between spaces, depth first; then it climbs to the next
storey where a shaft is clear all the way up (building A's stairwell), or starts afresh there
(carried up a stair the scene does not model: the irregular building has none).

:func:`lidar_scan` sweeps the lidar of :mod:`astralis_des.physics.lidar3d` at every stop (its
channels, vertical field, range and range noise, at ``RESOLUTION``; its slab test over the
scene's boxes, furniture included, which is 5 times faster than Bullet's ``rayTestBatch``
here). A level 16-channel unit sees no floor nearer than 4.9 m from 1.3 m up (its beams reach
15° down), nothing of a small room's floor: like a mapping drone's rotating mount, each stop
sweeps with the spin axis upright, then along x, then along y (an axis permutation keeps the
boxes axis-aligned for the slab test). Points are thinned to one per ``VOXEL`` cube.

:func:`write_cloud` writes a cloud as PLY or LAS/LAZ; :func:`scene_mesh` makes the scene's
boxes one mesh, and :func:`write_mesh` writes it (GLB Y-up, as glTF says).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from indoor_scenes import Rect, Scene, TrueRoom

from astralis_des.physics.lidar3d import Lidar3D, cast_boxes
from astralis_des.physics.sensors import NO_BODY

if TYPE_CHECKING:
    import trimesh

FLIGHT = 1.3  # m over each floor
STEP = 2.5  # m, the most between stops along a lane or a climb
LANE = 4.0  # m, the most between lanes
MARGIN = 0.5  # m kept from a room's walls
NEAR = 0.3  # m: a door this near a room's floor rectangle opens into it
VOXEL = 0.04  # m, the cloud's thinning cube
RESOLUTION = 0.4  # degrees between a channel's beams: a VLP-16 spinning at 20 Hz
SPINS = ((0, 1, 2), (1, 2, 0), (2, 0, 1))  # the world axes along the sensor's x, y, z:
# the spin axis is z (level), then x, then y
THIN_EVERY = 24  # stops between thinnings, keeping memory to a few sweeps' worth


@dataclass
class _Unit:
    room: TrueRoom
    stops: list[np.ndarray]


def flight(scene: Scene) -> np.ndarray:
    """The ``(K, 3)`` stops of a flight through every space and room of ``scene``, in
    order."""
    solids = np.array(scene.solids, dtype=float)
    floors = sorted(scene.floors)
    out: list[np.ndarray] = []
    came_up: np.ndarray | None = None
    for k, z in enumerate(floors):
        units = [_Unit(r, _lanes(r.rects, z + FLIGHT, solids))
                 for r in scene.spaces + scene.rooms if abs(r.floor - z) < 0.3]
        links = _links(scene, units, z, solids)
        entrances = [d for d in scene.doors if d.entrance and abs(d.floor - z) < 0.3]
        stops: list[np.ndarray] = []
        if came_up is not None:
            start = came_up[:2]
            stops.append(came_up)  # where a climb to the next storey may start again
        elif entrances:
            start = np.array(entrances[0].centre)
            stops.append(np.array([*start, z + FLIGHT]))
        else:
            start = np.array(units[0].room.rects[0][:2]) if units else np.zeros(2)
        if units:
            first = min(range(len(units)), key=lambda i: _rect_gap(units[i].room.rects, start))
            _visit(first, units, links, set(), stops)
        out += stops[1:] if came_up is not None else stops
        came_up = None
        if k + 1 < len(floors) and stops:
            climb = _climb(stops, floors[k + 1] + FLIGHT, solids)
            if climb is not None:
                out += climb
                came_up = climb[-1]
    return np.array(out)


def _lanes(rects: tuple[Rect, ...], z: float, solids: np.ndarray) -> list[np.ndarray]:
    """Stops on lanes along each rectangle's longer side, back and forth; none inside a
    solid (a pillar)."""
    stops = []
    for x0, y0, x1, y1 in rects:
        lo, hi = np.array([x0, y0]) + MARGIN, np.array([x1, y1]) - MARGIN
        mid = (np.array([x0, y0]) + np.array([x1, y1])) / 2
        lo, hi = np.where(lo < hi, lo, mid), np.where(lo < hi, hi, mid)
        along = int(np.argmax(hi - lo))
        across = 1 - along
        count = max(1, math.ceil((hi[across] - lo[across]) / LANE))
        lanes = lo[across] + (np.arange(count) + 0.5) * (hi[across] - lo[across]) / count
        line = _spread(lo[along], hi[along], STEP)
        for n, c in enumerate(lanes):
            for a in (line if n % 2 == 0 else line[::-1]):
                p = np.zeros(3)
                p[along], p[across], p[2] = a, c, z
                if not _inside(p, solids):
                    stops.append(p)
    return stops


def _spread(a: float, b: float, most: float) -> np.ndarray:
    """Evenly from ``a`` to ``b``, at most ``most`` apart (the middle when they are one)."""
    if b - a < 1e-9:
        return np.array([a])
    return np.linspace(a, b, math.ceil((b - a) / most) + 1)


def _links(scene: Scene, units: list[_Unit], z: float, solids: np.ndarray
           ) -> dict[int, list[tuple[int, np.ndarray]]]:
    """Which units each one leads to, and through which doorway or opening (a stop)."""
    links: dict[int, list[tuple[int, np.ndarray]]] = {i: [] for i in range(len(units))}
    joined: set[tuple[int, int]] = set()

    def join(i: int, j: int, xy: np.ndarray) -> None:
        if i != j and (min(i, j), max(i, j)) not in joined:
            joined.add((min(i, j), max(i, j)))
            stop = np.array([xy[0], xy[1], z + FLIGHT])
            links[i].append((j, stop))
            links[j].append((i, stop))

    for door in scene.doors:
        if door.entrance or abs(door.floor - z) > 0.3:
            continue
        xy = np.array(door.centre)
        gaps = sorted((_rect_gap(u.room.rects, xy), i) for i, u in enumerate(units))
        if len(gaps) > 1 and gaps[1][0] <= NEAR:
            join(gaps[0][1], gaps[1][1], xy)
    for i, a in enumerate(units):  # openings: rooms side by side with no wall between
        for j in range(i + 1, len(units)):
            for ra in a.room.rects:
                for rb in units[j].room.rects:
                    xy = _opening(ra, rb)
                    if xy is not None and not _inside(np.array([*xy, z + FLIGHT]), solids):
                        join(i, j, xy)
    return links


def _opening(a: Rect, b: Rect) -> np.ndarray | None:
    """The middle of where rectangles ``a`` and ``b`` face each other across less than a
    ``MARGIN`` gap, along at least a door's width (0.8 m); None if they do not."""
    for axis in (0, 1):
        gap = max(b[axis] - a[axis + 2], a[axis] - b[axis + 2])
        o = 1 - axis
        lo, hi = max(a[o], b[o]), min(a[o + 2], b[o + 2])
        if 0 <= gap < MARGIN and hi - lo >= 0.8:
            xy = np.zeros(2)
            xy[axis] = (min(a[axis + 2], b[axis + 2]) + max(a[axis], b[axis])) / 2
            xy[o] = (lo + hi) / 2
            return xy
    return None


def _visit(i: int, units: list[_Unit], links: dict[int, list[tuple[int, np.ndarray]]],
           seen: set[int], stops: list[np.ndarray]) -> None:
    """Depth first: unit ``i``'s lanes, then through each doorway into a unit not yet
    flown (and back the way it came, without stopping again)."""
    seen.add(i)
    lanes = units[i].stops
    if stops and lanes and _far(stops[-1], lanes[0]) > _far(stops[-1], lanes[-1]):
        lanes = lanes[::-1]  # from the end nearer where it came in
    stops += lanes
    for j, doorway in links[i]:
        if j not in seen:
            stops.append(doorway)
            _visit(j, units, links, seen, stops)


def _climb(stops: list[np.ndarray], top: float, solids: np.ndarray) -> list[np.ndarray] | None:
    """Stops straight up to ``top`` from the stop nearest the last one where nothing is in
    the way (0.3 m round), or None."""
    last = stops[-1]
    for p in sorted(stops, key=lambda s: _far(s, last)):
        lo, hi = p - [0.3, 0.3, 0.0], np.array([p[0] + 0.3, p[1] + 0.3, top])
        if not np.any(np.all(solids[:, 0] < hi, axis=1) & np.all(solids[:, 1] > lo, axis=1)):
            return [np.array([p[0], p[1], h]) for h in _spread(p[2], top, STEP)[1:]] \
                if top > p[2] else None
    return None


def _far(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b))


def _rect_gap(rects: tuple[Rect, ...], xy: np.ndarray) -> float:
    return min(math.hypot(max(r[0] - xy[0], 0.0, xy[0] - r[2]),
                          max(r[1] - xy[1], 0.0, xy[1] - r[3])) for r in rects)


def _inside(p: np.ndarray, solids: np.ndarray, margin: float = 0.1) -> bool:
    return bool(np.any(np.all((solids[:, 0] - margin <= p) & (p <= solids[:, 1] + margin),
                              axis=1)))


def lidar_scan(scene: Scene, seed: int = 0, voxel: float = VOXEL) -> np.ndarray:
    """``(N, 3)`` points of the lidar's sweeps at every stop of :func:`flight`, range noise
    drawn with ``seed``, thinned to one per ``voxel`` cube."""
    rng = np.random.default_rng(seed)
    lidar = Lidar3D(None, NO_BODY, rng=rng,  # type: ignore[arg-type]  # its beams, no client
                    resolution=RESOLUTION)
    solids = np.array(scene.solids, dtype=float)
    kept: list[np.ndarray] = []
    for n, stop in enumerate(flight(scene), start=1):
        for spin in SPINS:
            kept.append(_sweep(lidar, stop, solids, spin, rng.uniform(0.0, math.tau)))
        if n % THIN_EVERY == 0:
            kept = [thin(np.concatenate(kept), voxel)]
    return thin(np.concatenate(kept), voxel)


def _sweep(lidar: Lidar3D, centre: np.ndarray, solids: np.ndarray, spin: tuple[int, ...],
           heading: float) -> np.ndarray:
    """One sweep's points, the spin axis along world axis ``spin[2]``."""
    axes = list(spin)
    c, lo, hi = centre[axes], solids[:, 0][:, axes], solids[:, 1][:, axes]
    dirs = lidar.directions(heading)
    t, _ = cast_boxes(c, dirs, heading, lidar.elevations, lidar.step, lo, hi, lidar.start,
                      lidar.range_max)
    assert lidar.rng is not None
    ranges = t + lidar.rng.normal(0.0, lidar.noise_std, t.shape)
    hit = np.isfinite(t) & (ranges >= lidar.range_min) & (t <= lidar.range_max)
    out = np.empty((int(hit.sum()), 3))
    out[:, axes] = c + ranges[hit][:, None] * dirs[hit]
    return out


def thin(points: np.ndarray, voxel: float) -> np.ndarray:
    """The first point in each ``voxel`` cube."""
    keys = np.floor(points / voxel).astype(np.int64)
    keys -= keys.min(axis=0)
    span = keys.max(axis=0) + 1
    flat = (keys[:, 0] * span[1] + keys[:, 1]) * span[2] + keys[:, 2]
    _, first = np.unique(flat, return_index=True)
    return points[np.sort(first)]


def write_cloud(points: np.ndarray, path: Path) -> Path:
    """``points`` as a binary PLY (float64 x, y, z) or a LAS/LAZ (1 mm steps), by suffix."""
    path = Path(path)
    xyz = np.asarray(points, dtype="<f8")
    if path.suffix.lower() == ".ply":
        header = ("ply\nformat binary_little_endian 1.0\n"
                  f"element vertex {len(xyz)}\nproperty double x\nproperty double y\n"
                  "property double z\nend_header\n")
        path.write_bytes(header.encode("ascii") + np.ascontiguousarray(xyz).tobytes())
        return path
    import laspy

    header = laspy.LasHeader(point_format=0, version="1.2")
    header.scales = np.array([0.001, 0.001, 0.001])
    header.offsets = np.floor(xyz.min(axis=0))
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    las.write(str(path))
    return path


def scene_mesh(scene: Scene) -> trimesh.Trimesh:
    """The scene's boxes (walls, slabs, furniture), each a closed box of 12 triangles, as one
    mesh; where boxes meet or overlap their faces stay as they are."""
    import trimesh

    solids = np.array(scene.solids, dtype=float)
    unit = trimesh.creation.box(bounds=[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])  # faces outwards
    corners = np.asarray(unit.vertices)
    vertices = solids[:, None, 0] + corners[None] * (solids[:, 1] - solids[:, 0])[:, None]
    faces = np.asarray(unit.faces)[None] + len(corners) * np.arange(len(solids))[:, None, None]
    return trimesh.Trimesh(vertices.reshape(-1, 3), faces.reshape(-1, 3), process=False)


def write_mesh(scene: Scene, path: Path) -> Path:
    """:func:`scene_mesh` as OBJ (Z-up, as the scene) or GLB (turned Y-up, as glTF says), by
    suffix."""
    mesh = scene_mesh(scene)
    path = Path(path)
    if path.suffix.lower() in (".glb", ".gltf"):
        v = np.asarray(mesh.vertices)
        mesh.vertices = np.column_stack([v[:, 0], v[:, 2], -v[:, 1]])  # Z-up to Y-up
    mesh.export(str(path))
    return path
