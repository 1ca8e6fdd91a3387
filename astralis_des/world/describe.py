"""``astralis world rooms WORLD``: what a mission file can name in a world, as rows."""

from __future__ import annotations

from dataclasses import dataclass

from astralis_des.world.model import World


@dataclass(frozen=True)
class RoomRow:
    building: str
    storey: int
    segment: str
    room: str
    box: tuple[float, float, float, float]  # x0, y0, x1, y1 (m)
    area: float  # m^2
    door: tuple[float, float, float]
    corridor: str


def room_rows(world: World) -> list[RoomRow]:
    """Every room, by building, storey, segment and id."""
    rows = []
    for rid in sorted(world.rooms, key=lambda r: (world.rooms[r].building, world.rooms[r].floor,
                                                  world.rooms[r].segment, r)):
        room = world.rooms[rid]
        lo, hi = room.box.lo, room.box.hi
        rows.append(RoomRow(room.building, room.floor, room.segment, rid,
                            (lo[0], lo[1], hi[0], hi[1]), room.area,
                            tuple(float(v) for v in room.door.center), room.corridor))  # type: ignore[arg-type]
    return rows


def headline(world: World) -> str:
    parts = []
    for bid in sorted(world.buildings):
        b = world.buildings[bid]
        n = sum(1 for r in world.rooms.values() if r.building == bid)
        lift = ", a vehicle lift" if b.lift is not None else ""
        parts.append(f"{bid}: {b.floors} storeys of {b.floor_height:g} m, {n} rooms{lift}")
    inner = world.interior
    if inner is not None:
        n = sum(1 for r in world.rooms.values() if r.building == inner.group)
        parts.append(f"{inner.group}: found in a scan or model, {len(inner.storeys)} storeys, "
                     f"{n} rooms, {len(inner.openings)} doors, {len(inner.stairs)} stairs")
    return (f"world {world.name}: site {world.site[0]:g} x {world.site[1]:g} m; "
            f"{len(world.segments)} segments, {len(world.rooms)} rooms"
            + ("; " + "; ".join(parts) if parts else ""))


def room_lines(world: World) -> list[str]:
    """The headline, then a line a room (plain text: it is read, grepped and pasted)."""
    rows = room_rows(world)
    width = max([len(r.room) for r in rows] + [4])
    seg = max([len(r.segment) for r in rows] + [7])
    lines = [headline(world),
             f"{'room':<{width}}  {'segment':<{seg}}  storey  {'x0..x1, y0..y1 (m)':<26}"
             f"  {'area m2':>7}  {'door x, y, z':<18}  corridor"]
    for r in rows:
        x0, y0, x1, y1 = r.box
        box = f"{x0:g}..{x1:g}, {y0:g}..{y1:g}"
        door = ", ".join(f"{v:g}" for v in r.door)
        lines.append(f"{r.room:<{width}}  {r.segment:<{seg}}  {r.storey:>6}  {box:<26}  "
                     f"{r.area:7.1f}  {door:<18}  {r.corridor}")
    return lines
