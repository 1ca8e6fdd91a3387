"""A world file's ``interior:`` built: its rooms and halls become searched rooms (a room's
door is the one onto a corridor where it has one), its corridors and stairwells passages, and
its doors and stairs what routes go through (:mod:`.interior_routes`).

Every reference is checked here, where the file's lines are known: a door or stairs naming a
place that is not there, a place on a storey that is not, a room no door leads to.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from astralis_des.world.geometry import Box, inside_polygon
from astralis_des.world.interior_walls import interior_bounds
from astralis_des.world.parts import Door, InteriorPlan, Opening, Room, Segment, Space, Stair
from astralis_des.world.spec import OUTSIDE, InteriorSpec, PlaceSpec, robot
from astralis_des.yamlio import LocatedYaml

SEAT_CELL = 0.1  # m, the grid a place's seat is found on
KEY = "interior"


def interior_parts(spec: InteriorSpec, doc: LocatedYaml) -> tuple[
        dict[str, Room], dict[str, Segment], dict[str, Space], InteriorPlan]:
    """The rooms, segments and passages of ``spec`` and its plan (doors, stairs, seats); a
    broken reference is an InputError at its key."""
    levels = {s.level: s for s in spec.storeys}
    places: dict[str, PlaceSpec] = {}
    for i, place in enumerate(spec.places):
        where = (KEY, "places", i, "id")
        if not place.id.startswith(f"{spec.group}."):
            raise doc.error(where, f"'{place.id}' is not in group '{spec.group}' (its ids "
                            f"start with '{spec.group}.')")
        if place.storey not in levels:
            raise doc.error(where, f"'{place.id}' is on storey {place.storey}, and there are "
                            f"{len(levels)}")
        if place.id in places:
            raise doc.error(where, f"id '{place.id}' is used twice")
        places[place.id] = place
    openings = [_opening(spec, i, places, doc) for i in range(len(spec.doors))]
    stairs = []
    for i, stair in enumerate(spec.stairs):
        a, b = (_known(places, name, doc, (KEY, "stairs", i, "between")) for name in
                stair.between)
        if abs(a.storey - b.storey) != 1:
            raise doc.error((KEY, "stairs", i, "between"), f"stairs join storeys one above the "
                            f"other: '{a.id}' is on {a.storey}, '{b.id}' on {b.storey}")
        stairs.append(Stair((a.id, b.id), tuple(stair.passable_by)))
    boxes = {p.id: _box(p, spec) for p in places.values()}
    seats = {pid: (*_seat(p), boxes[pid].lo[2]) for pid, p in places.items()}
    rooms: dict[str, Room] = {}
    spaces: dict[str, Space] = {}
    for i, place in enumerate(spec.places):
        box = boxes[place.id]
        if not place.searched:
            kind = "passage" if place.kind == "corridor" else "stairs"
            spaces[place.id] = Space(place.id, kind, spec.group, place.storey, box)
            continue
        if min(box.size[:2]) < robot()[1]:
            kind, length = robot()
            raise doc.error((KEY, "places", i, "outline"), f"'{place.id}' is {box.size[0]:.2f}"
                            f" x {box.size[1]:.2f} m: smaller than a robot (a {kind} is "
                            f"{length:g} m long); make it a corridor or leave it out")
        door, onto = _main_door(place, openings, places, doc, i)
        rect = _is_rectangle(place)
        rooms[place.id] = Room(place.id, spec.group, place.storey, place.id.rsplit(".", 1)[0],
                               box, door, onto, () if rect else tuple(place.outline),
                               None if rect else seats[place.id][:2])
    segments: dict[str, list[str]] = {}
    for room in rooms.values():
        segments.setdefault(room.segment, []).append(room.id)
    (x0, y0), (x1, y1) = interior_bounds(spec)
    top = max(b.hi[2] for b in boxes.values())
    plan = InteriorPlan(spec.group, tuple(s.z for s in spec.storeys), tuple(openings),
                        tuple(stairs), Box((x0, y0, spec.storeys[0].z), (x1, y1, top)), seats,
                        {p.id: tuple(p.outline) for p in spec.places})
    return rooms, {s: Segment(s, spec.group, int(s.split(".")[1]), tuple(ids))
                   for s, ids in segments.items()}, spaces, plan


def _known(places: dict[str, PlaceSpec], name: str, doc: LocatedYaml,
           where: tuple[str | int, ...]) -> PlaceSpec:
    if name not in places:
        raise doc.error(where, f"no place '{name}' in the interior")
    return places[name]


def _opening(spec: InteriorSpec, i: int, places: dict[str, PlaceSpec],
             doc: LocatedYaml) -> Opening:
    door = spec.doors[i]
    where = (KEY, "doors", i, "between")
    first, second = door.between
    if first == OUTSIDE:
        first, second = second, first
    a = _known(places, first, doc, where)
    b = None if second == OUTSIDE else _known(places, second, doc, where)
    if b is not None and b.storey != a.storey:
        raise doc.error(where, f"a door joins places of one storey: '{a.id}' is on "
                        f"{a.storey}, '{b.id}' on {b.storey}")
    z = spec.storeys[a.storey - 1].z
    return Opening(Door((door.at[0], door.at[1], z), 0 if door.across == "x" else 1,
                        door.width, door.height), (a.id, None if b is None else b.id))


def _main_door(place: PlaceSpec, openings: list[Opening], places: dict[str, PlaceSpec],
               doc: LocatedYaml, i: int) -> tuple[Door, str]:
    """The room's door onto a passage where it has one, else out of the building, else its
    first; and what is on its other side."""
    own = [(o, o.places[1] if o.places[0] == place.id else o.places[0]) for o in openings
           if place.id in o.places]
    if not own:
        raise doc.error((KEY, "places", i, "id"), f"no door leads into '{place.id}': add one "
                        "to interior.doors, or leave the room out")

    def rank(item: tuple[Opening, str | None]) -> int:
        other = item[1]
        return 0 if other is not None and not places[other].searched else \
            1 if other is None else 2

    door, other = min(own, key=rank)
    return door.door, other or OUTSIDE


def _box(place: PlaceSpec, spec: InteriorSpec) -> Box:
    xy = np.asarray(place.outline, dtype=float)
    storey = spec.storeys[place.storey - 1]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    return Box((float(lo[0]), float(lo[1]), storey.z),
               (float(hi[0]), float(hi[1]), storey.z + storey.height))


def _is_rectangle(place: PlaceSpec) -> bool:
    xy = np.asarray(place.outline, dtype=float)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    on_edge = np.isclose(xy, lo) | np.isclose(xy, hi)
    return bool(len(xy) == 4 and on_edge.all())


def _seat(place: PlaceSpec) -> tuple[float, float]:
    """The point of the place's floor farthest from its outline (a rectangle's centre)."""
    xy = np.asarray(place.outline, dtype=float)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    if _is_rectangle(place):
        return (float(lo[0] + hi[0]) / 2, float(lo[1] + hi[1]) / 2)
    n = np.maximum(np.ceil((hi - lo) / SEAT_CELL).astype(int), 1)
    gx, gy = np.meshgrid(lo[0] + (np.arange(n[0]) + 0.5) * SEAT_CELL,
                         lo[1] + (np.arange(n[1]) + 0.5) * SEAT_CELL, indexing="ij")
    cells = np.column_stack([gx.ravel(), gy.ravel()])
    inside = inside_polygon(cells, xy).reshape(n[0], n[1])
    if not inside.any():
        return (float(xy[:, 0].mean()), float(xy[:, 1].mean()))
    depth = ndimage.distance_transform_edt(np.pad(inside, 1))[1:-1, 1:-1]
    best = int(np.argmax(depth))
    return (round(float(cells[best, 0]), 3), round(float(cells[best, 1]), 3))
