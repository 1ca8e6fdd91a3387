"""Build a :class:`World` from a world file: rooms, doors, corridors, stairwells and walls.

Every floor of a building repeats one plan: a stairwell at the west end, a corridor along x,
segments of rooms on its north and south sides, a lobby at the east end with the entrance.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from astralis_des.errors import InputError
from astralis_des.kinds import KINDS
from astralis_des.world.geometry import Box
from astralis_des.world.imported import Imported, area_rooms, ground_slab, load_geometry
from astralis_des.world.interior import interior_parts
from astralis_des.world.interior_walls import interior_solids
from astralis_des.world.model import Building, Door, Room, Segment, Solid, Space, World
from astralis_des.world.spec import BuildingSpec, WorldSpec
from astralis_des.yamlio import LocatedYaml, read_bytes

LIFT_LENGTH = 2.4  # m along x: the vehicle lift's platform (the UGV turns on it)
LANDING = 1.2  # m at least between the lift's shaft and the corridor, on every floor


@dataclass
class _Parts:
    rooms: dict[str, Room]
    segments: dict[str, Segment]
    spaces: dict[str, Space]
    solids: list[Solid]


def build_world(spec: WorldSpec, blocks: list[Solid] | None = None,
                imported: Imported | None = None, doc: LocatedYaml | None = None) -> World:
    """The world of ``spec``: its buildings, areas, interior and obstacles, and an imported
    world's ``blocks`` (read from beside the file by :func:`load_world`; ``doc`` locates an
    error in the interior)."""
    parts = _Parts({}, {}, {}, [])
    plan = None
    if spec.interior is not None:
        rooms, segments, spaces, plan = interior_parts(
            spec.interior, doc or LocatedYaml({}, {}, Path("<world>")))
        parts.rooms.update(rooms)
        parts.segments.update(segments)
        parts.spaces.update(spaces)
        parts.solids.extend(interior_solids(spec.interior))
    buildings = {b.id: _add_building(b, parts) for b in spec.buildings}
    for obstacle in spec.obstacles:
        cx, cy = obstacle.center
        sx, sy, sz = obstacle.size
        box = Box((cx - sx / 2, cy - sy / 2, 0.0), (cx + sx / 2, cy + sy / 2, sz))
        parts.solids.append(Solid(obstacle.kind, box, obstacle.kind))
    if spec.areas:
        rooms, segments = area_rooms(spec.areas)
        parts.rooms.update(rooms)
        parts.segments.update(segments)
    if spec.areas or spec.interior is not None:
        parts.solids.append(ground_slab(spec.site.size))
    parts.solids.extend(blocks or [])
    roads = tuple(Solid("road", _road_box(r.start, r.end, r.width), "road") for r in spec.roads)
    return World(
        name=spec.name, site=spec.site.size, buildings=buildings, segments=parts.segments,
        rooms=parts.rooms, spaces=parts.spaces, solids=tuple(parts.solids),
        stairs_passable_by={b.id: tuple(b.stairs_passable_by) for b in spec.buildings},
        surfaces=roads, imported=imported, interior=plan,
        origin=None if spec.site.origin is None else (
            spec.site.origin.latitude, spec.site.origin.longitude, spec.site.origin.altitude),
    )


def _road_box(start: tuple[float, float], end: tuple[float, float], width: float) -> Box:
    """An axis-aligned road (a road in any other direction gets its bounding box)."""
    lo = (min(start[0], end[0]), min(start[1], end[1]))
    hi = (max(start[0], end[0]), max(start[1], end[1]))
    pad_x = width / 2 if hi[1] - lo[1] > hi[0] - lo[0] else 0.0
    pad_y = width / 2 if pad_x == 0.0 else 0.0
    return Box((lo[0] - pad_x, lo[1] - pad_y, 0.0), (hi[0] + pad_x, hi[1] + pad_y, 0.02))


def load_world(path: Path) -> World:
    """Read, validate and build a world file. Built once for each content of the file and
    set of robot kinds: a file edited between two loads in one process (a notebook, a
    server) is read anew, and so is one loaded again after a plug-in added a kind (its
    routes and stairs are for every kind)."""
    try:  # a FIFO or a device is refused, never read
        digest = hashlib.sha256(read_bytes(path)).hexdigest()
    except InputError:
        digest = ""  # load_yaml says what is wrong with the path
    return _built(Path(path), digest, tuple(KINDS))


@lru_cache(maxsize=16)
def _built(path: Path, _digest: str, _kinds: tuple[str, ...]) -> World:
    return read_world(path)


def read_world(path: Path) -> World:
    """Read, validate and build a world file, every time (:func:`load_world` builds once)."""
    from astralis_des.validation import check_unique_ids, validate
    from astralis_des.yamlio import load_yaml

    doc = load_yaml(path)
    check_unique_ids(doc, "buildings")
    check_unique_ids(doc, "areas")
    spec = validate(WorldSpec, doc)
    _check_areas(spec, doc)
    blocks, imported = None, None
    if spec.geometry is not None:
        blocks, imported = load_geometry(spec.geometry, spec.source, doc)
    world = build_world(spec, blocks, imported, doc)
    footprints = [world.buildings[b.id].footprint for b in spec.buildings]
    for i, box in enumerate(footprints):
        if box.lo[0] < 0 or box.lo[1] < 0 or box.hi[0] > spec.site.size[0] or \
                box.hi[1] > spec.site.size[1]:
            raise doc.error(("buildings", i, "origin"),
                            f"building {spec.buildings[i].id} reaches outside the site "
                            f"({box.hi[0]:g} x {box.hi[1]:g} m at its far corner)")
        for j in range(i):
            other = footprints[j]
            if all(box.lo[k] < other.hi[k] and other.lo[k] < box.hi[k] for k in (0, 1)):
                raise doc.error(("buildings", i, "origin"),
                                f"building {spec.buildings[i].id} overlaps building "
                                f"{spec.buildings[j].id}")
    return world


def _check_areas(spec: WorldSpec, doc: LocatedYaml) -> None:
    buildings = {b.id for b in spec.buildings}
    sx, sy = spec.site.size
    for i, area in enumerate(spec.areas):
        group = area.id.split(".")[0]
        if group in buildings:
            raise doc.error(("areas", i, "id"), f"'{group}' is a building's id; areas need a "
                            "group of their own (the first part of the id)")
        (x0, y0, _), (x1, y1, _) = area.box
        if x0 < 0 or y0 < 0 or x1 > sx or y1 > sy:
            raise doc.error(("areas", i, "box"), f"area {area.id} reaches outside the site "
                            f"({sx:g} x {sy:g} m)")


def _add_building(b: BuildingSpec, parts: _Parts) -> Building:
    ox, oy = b.origin
    t, h = b.wall_thickness, b.floor_height
    rw, rd = b.room_size
    sides = {side: [s for s in b.segments if s.side == side] for side in ("south", "north")}
    count = {side: sum(s.rooms for s in segs) for side, segs in sides.items()}
    depth = {side: rd if count[side] else 0.0 for side in sides}
    x_stair = ox + b.stairwell_width
    x_east = x_stair + max(count.values()) * rw + b.lobby_length
    y_lo = oy + depth["south"]  # corridor's south line
    y_hi = y_lo + b.corridor_width  # corridor's north line
    y_north = y_hi + depth["north"]
    top = b.floors * h
    yc = (y_lo + y_hi) / 2
    # the vehicle lift: a shaft as wide as the corridor at the stairwell's far (west) end,
    # leaving a landing of at least LANDING before the corridor
    lift_x1 = ox + t / 2 + max(min(LIFT_LENGTH, b.stairwell_width - t - LANDING), 0.5)
    lift = Box((ox + t / 2, y_lo + t / 2, 0.0), (lift_x1, y_hi - t / 2, top - t))

    for floor in range(1, b.floors + 1):
        z = (floor - 1) * h
        inner_top = z + h - t
        corridor_id = f"{b.id}.{floor}.corridor"
        parts.spaces[corridor_id] = Space(
            corridor_id, "corridor", b.id, floor,
            Box((x_stair, y_lo + t / 2, z), (x_east - t / 2, y_hi - t / 2, inner_top)))
        doors: dict[str, list[float]] = {"south": [], "north": []}
        for side, segs in sides.items():
            x = x_stair
            for seg_index, seg in enumerate(b.segments, start=1):
                if seg not in segs:
                    continue
                seg_id = f"{b.id}.{floor}.{seg_index}"
                room_ids = []
                for r in range(1, seg.rooms + 1):
                    room_id = f"{seg_id}.{r}"
                    y0, y1 = (oy, y_lo) if side == "south" else (y_hi, y_north)
                    door_y = y_lo if side == "south" else y_hi
                    door = Door((x + rw / 2, door_y, z), 1, b.door_width, b.door_height)
                    box = Box((x + t / 2, y0 + t / 2, z), (x + rw - t / 2, y1 - t / 2, inner_top))
                    parts.rooms[room_id] = Room(room_id, b.id, floor, seg_id, box, door,
                                                corridor_id)
                    doors[side].append(x + rw / 2)
                    room_ids.append(room_id)
                    x += rw
                parts.segments[seg_id] = Segment(seg_id, b.id, floor, tuple(room_ids))
        walls = _floor_walls(b, z, x_stair, x_east, y_lo, y_hi, y_north, doors, floor == 1)
        parts.solids.extend(Solid("wall", w, f"{b.id}.{floor}") for w in walls)
        slab_x0 = ox if floor == 1 else x_stair  # the stair shaft is open above the ground
        parts.solids.append(Solid("slab", Box((slab_x0, oy, z - t), (x_east, y_north, z)),
                                  f"{b.id}.{floor} floor"))
        if floor > 1:  # the landing between the corridor and the lift's shaft
            parts.solids.append(Solid("slab", Box((lift.hi[0], y_lo, z - t), (x_stair, y_hi, z)),
                                      f"{b.id}.{floor} landing"))
    parts.solids.append(Solid("slab", Box((ox, oy, top - t), (x_east, y_north, top)),
                              f"{b.id} roof"))
    for y in (lift.lo[1] - t / 2, lift.hi[1] + t / 2):  # the shaft's sides; open to the landing
        parts.solids.append(Solid("wall", Box((ox, y - t / 2, 0.0), (lift.hi[0], y + t / 2,
                                                                      top - t)),
                                  f"{b.id} lift shaft"))
    parts.spaces[f"{b.id}.stairwell"] = Space(
        f"{b.id}.stairwell", "stairwell", b.id, 0,
        Box((ox + t / 2, oy + t / 2, 0.0), (x_stair - t / 2, y_north - t / 2, top - t)))
    return Building(b.id, Box((ox, oy, 0.0), (x_east, y_north, top)), b.floors, h,
                    entrance=(x_east + 1.5, yc, 0.0), lift=lift)


def _floor_walls(
    b: BuildingSpec, z: float, x_stair: float, x_east: float, y_lo: float, y_hi: float,
    y_north: float, doors: dict[str, list[float]], ground: bool,
) -> list[Box]:
    ox, oy = b.origin
    t, top = b.wall_thickness, z + b.floor_height - b.wall_thickness
    rw = b.room_size[0]

    def wall(axis: int, at: float, a: float, c: float, gaps: list[float],
             width: float) -> list[Box]:
        """Wall on the line ``coord[axis] == at`` from ``a`` to ``c``, with door gaps."""
        out: list[Box] = []
        start = a
        cuts = [(g - width / 2, g + width / 2) for g in sorted(gaps)] + [(c, c)]
        for lo, hi in cuts:
            if lo > start:
                out.append(_wall_box(axis, at, start, lo, z, top, t))
            if hi > lo:
                out.append(_wall_box(axis, at, lo, hi, z + b.door_height, top, t))
            start = hi
        return out

    walls = wall(1, oy, ox, x_east, [], 0.0) + wall(1, y_north, ox, x_east, [], 0.0)
    walls += wall(0, ox, oy, y_north, [], 0.0)
    entrance_width = min(1.6, b.corridor_width - 0.4)
    walls += wall(0, x_east, oy, y_north, [(y_lo + y_hi) / 2] if ground else [], entrance_width)
    for side, line, far in (("south", y_lo, oy), ("north", y_hi, y_north)):
        if not doors[side]:
            continue
        walls += wall(1, line, x_stair, x_east, doors[side], b.door_width)
        lo, hi = sorted((line, far))
        walls += wall(0, x_stair, lo, hi, [], 0.0)
        walls += [_wall_box(0, x_stair + k * rw, lo, hi, z, top, t)
                  for k in range(1, len(doors[side]) + 1)]
    return walls


def _wall_box(axis: int, at: float, a: float, c: float, z0: float, z1: float, t: float) -> Box:
    if axis == 0:  # the wall is the line x == at
        return Box((at - t / 2, a, z0), (at + t / 2, c, z1))
    return Box((a, at - t / 2, z0), (c, at + t / 2, z1))
