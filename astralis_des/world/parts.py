"""The parts a world is made of: rooms and their doors, spaces (corridors, stairwells,
areas), solids (walls, slabs, imported blocks), segments and buildings."""

from __future__ import annotations

from dataclasses import dataclass

from astralis_des.world.geometry import Box


@dataclass(frozen=True)
class Door:
    """An opening in a wall: ``center`` on the wall line at floor height."""

    center: tuple[float, float, float]
    normal_axis: int  # 0: the wall is normal to x, 1: normal to y
    width: float
    height: float


@dataclass(frozen=True)
class Room:
    """A searchable room; ``id`` reads building.floor.segment.room, e.g. ``A.2.1.3``."""

    id: str
    building: str
    floor: int
    segment: str
    box: Box
    door: Door
    corridor: str
    # a room found in a scan or model (``interior:``) that is no rectangle: its floor's
    # outline (``box`` is its bounds) and the point of its floor farthest from its walls
    outline: tuple[tuple[float, float], ...] = ()
    seat: tuple[float, float] | None = None

    @property
    def center(self) -> tuple[float, float, float]:
        """Centre of the floor of the room (of a room that is no rectangle: its seat)."""
        if self.seat is not None:
            return (self.seat[0], self.seat[1], self.box.lo[2])
        c = self.box.center
        return (c[0], c[1], self.box.lo[2])

    @property
    def area(self) -> float:
        sx, sy, _ = self.box.size
        return sx * sy

    def door_point(self, side: str = "corridor", offset: float = 0.6) -> tuple[float, float, float]:
        """A point ``offset`` beyond the door's wall, on the room or the corridor side."""
        axis = self.door.normal_axis
        inward = 1.0 if self.box.center[axis] > self.door.center[axis] else -1.0
        edge = self.box.lo[axis] if inward > 0 else self.box.hi[axis]
        gap = abs(edge - self.door.center[axis]) + offset
        point = list(self.door.center)
        point[axis] += inward * gap if side == "room" else -inward * gap
        return (point[0], point[1], point[2])


@dataclass(frozen=True)
class Space:
    """A convex walkable volume (corridor, stairwell): straight lines inside it are free."""

    id: str
    kind: str
    building: str
    floor: int
    box: Box


BLOCK = "block"  # the kind of an imported world's voxel boxes


@dataclass(frozen=True)
class Solid:
    """Static geometry: a wall, slab or outdoor obstacle, as an axis-aligned box."""

    kind: str
    box: Box
    label: str = ""


@dataclass(frozen=True)
class Segment:
    id: str
    building: str
    floor: int
    rooms: tuple[str, ...]


@dataclass(frozen=True)
class Building:
    id: str
    footprint: Box  # full height
    floors: int
    floor_height: float
    entrance: tuple[float, float, float]  # just outside the entrance door, at ground level
    lift: Box | None = None  # the vehicle lift's shaft in the stairwell (from the ground up)


@dataclass(frozen=True)
class Opening:
    """A door of an interior found in a scan or model, between two of its places (rooms,
    halls, corridors, stairwells); ``None`` is the outside (an entrance)."""

    door: Door
    places: tuple[str, str | None]


@dataclass(frozen=True)
class Stair:
    """Stairs between two places of an interior on storeys one above the other."""

    places: tuple[str, str]
    kinds: tuple[str, ...]


@dataclass(frozen=True)
class InteriorPlan:
    """A building found in a scan or model: its places (searched rooms are in the world's
    ``rooms``, passages in its ``spaces``), doors, stairs and storeys' floor heights."""

    group: str
    storeys: tuple[float, ...]  # z of each storey's floor, lowest first
    openings: tuple[Opening, ...]
    stairs: tuple[Stair, ...]
    footprint: Box  # the bounds of its places, from the lowest floor to the top storey's top
    seats: dict[str, tuple[float, float, float]]  # every place's seat (floor height)
    outlines: dict[str, tuple[tuple[float, float], ...]]  # every place's floor, xy
