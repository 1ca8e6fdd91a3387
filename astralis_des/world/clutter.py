"""Clutter by messiness: furniture and bystanders placed on a room's free floor.

Every candidate spot is found at once on the room's grid (summed-area tables of what is free),
then spots are tried in random order: one is kept if the free floor, shrunk by half the passage
width, stays reachable from the door. Items that do not fit are reported, never raised.
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np

from astralis_des.compiled import kernels
from astralis_des.errors import suggest
from astralis_des.streams import stream
from astralis_des.world.catalogue import Catalogue, agree, avatar_size, default_catalogue
from astralis_des.world.freespace import BoolArray, FreeSpace, room_free_space
from astralis_des.world.geometry import Box
from astralis_des.world.grids import summed, wall_sides, wall_windows, window
from astralis_des.world.model import Room, World
from astralis_des.world.placing import Occupancy, disk_rows

ATTEMPTS = 30  # spots tried per item before it is skipped
CUT_OFF = "every spot tried cuts off free floor from the door"
AVATAR = "avatar"


@dataclass(frozen=True)
class Placed:
    """One placed item; ``size`` is its axis-aligned extent once turned by ``yaw``."""

    kind: str
    room: str
    center: tuple[float, float, float]
    size: tuple[float, float, float]
    yaw: float  # 0 or pi/2
    attributes: tuple[tuple[str, object], ...] = ()  # Table II attributes of an avatar

    @property
    def box(self) -> Box:
        c, s = self.center, self.size
        return Box((c[0] - s[0] / 2, c[1] - s[1] / 2, c[2] - s[2] / 2),
                   (c[0] + s[0] / 2, c[1] + s[1] / 2, c[2] + s[2] / 2))


@dataclass(frozen=True)
class Clutter:
    placed: tuple[Placed, ...] = ()
    skipped: tuple[tuple[str, str, str], ...] = ()  # (room, kind, reason)

    def in_room(self, room_id: str) -> tuple[Placed, ...]:
        return tuple(p for p in self.placed if p.room == room_id)


@dataclass(frozen=True)
class Spot:
    """Where ``place_in`` put a footprint: centre, axis-aligned extent and yaw."""

    center: tuple[float, float]
    extent: tuple[float, float]
    yaw: float


def place_room(world: World, room_id: str, messiness: float, rng: np.random.Generator,
               catalogue: Catalogue | None = None) -> Clutter:
    """Furniture, then bystanders, in one room; what does not fit is listed in ``skipped``."""
    if not 0.0 <= messiness <= 1.0:
        raise ValueError(f"messiness must be in [0, 1], got {messiness}")
    if catalogue is None:
        catalogue = default_catalogue()
    space = room_free_space(world, room_id)
    occupancy = Occupancy.empty(space, door_keepout(space, world.rooms[room_id], catalogue),
                                catalogue.passage)
    placed: list[Placed] = []
    skipped: list[tuple[str, str, str]] = []

    def put(kind: str, size: tuple[float, float, float], against_wall: bool, clearance: float,
            attributes: tuple[tuple[str, object], ...] = ()) -> None:
        spot = place_in(space, occupancy, size[:2], rng, against_wall=against_wall,
                        clearance=clearance, passage=catalogue.passage)
        if isinstance(spot, str):
            skipped.append((room_id, kind, spot))
            return
        center = (*spot.center, space.floor_z + size[2] / 2)
        placed.append(Placed(kind, room_id, center, (*spot.extent, size[2]), spot.yaw,
                             attributes))

    area = space.area
    for kind, item in catalogue.items.present().items():
        for _ in range(_count(messiness * item.per_10m2_at_full * area / 10)):
            put(kind, _size(rng, item.size_min, item.size_max), item.against_wall,
                item.clearance)
    avatars = catalogue.avatars
    free_chairs = [p for p in placed if p.kind == "chair"]
    for _ in range(_count(messiness * avatars.per_room_at_full)):
        attributes = _draw_attributes(catalogue, rng)
        values = dict(attributes)
        body = avatar_size(str(values["activity"]), str(values["height"]))
        if values["activity"] == "sitting":
            seat = _seat(free_chairs, catalogue, rng, put, placed)
            if seat is not None:  # on a chair: the room's, or one brought for it
                placed.append(Placed(AVATAR, room_id, (seat.center[0], seat.center[1],
                                                       space.floor_z + body[2] / 2),
                                     body, seat.yaw, attributes))
                continue
        put(AVATAR, body, False, avatars.clearance, attributes)
    return Clutter(tuple(placed), tuple(skipped))


def _seat(free: list[Placed], catalogue: Catalogue, rng: np.random.Generator,
          put: Callable[..., None], placed: list[Placed]) -> Placed | None:
    """A chair for a sitting avatar: one of the room's free chairs at random, else a new
    one placed for it (none if the catalogue has no chairs, or none fits)."""
    if free:
        return free.pop(int(rng.integers(len(free))))
    chair = catalogue.items.present().get("chair")
    if chair is None:
        return None
    before = len(placed)
    put("chair", _size(rng, chair.size_min, chair.size_max), chair.against_wall,
        chair.clearance)
    return placed[-1] if len(placed) > before else None


MEMO_ROOMS = 4096  # furnished rooms a world keeps in memory (a tune's trials reuse them)


def furnish(world: World, room_id: str, messiness: float, seed: int, index: int,
            catalogue: Catalogue) -> Clutter:
    """:func:`place_room` with the room's own generator, ``stream(seed, "clutter", index)``.

    The result depends on its arguments alone, so it is kept on the world: the same room,
    messiness and seed in a later mission of this process (a study's next variant, a tune's next
    trial) is furnished from memory, identical to placing it again.
    """
    memo = world.memo("furnished", MEMO_ROOMS)
    key = (room_id, messiness, seed, index)
    found = memo.get(key)
    if found is not None and found[0] is catalogue:
        return found[1]
    clutter = place_room(world, room_id, messiness, stream(seed, "clutter", index), catalogue)
    memo[key] = (catalogue, clutter)
    return clutter


def place_world(world: World, messiness: Mapping[str, float], seed: int,
                catalogue: Catalogue | None = None) -> Clutter:
    """Clutter in each room of ``messiness``; a room's result depends only on it and the seed."""
    order = sorted(world.rooms)
    unknown = [r for r in messiness if r not in world.rooms]
    if unknown:
        raise ValueError(f"unknown room {unknown[0]!r}; {suggest(unknown[0], order)}")
    placed: list[Placed] = []
    skipped: list[tuple[str, str, str]] = []
    for index, room_id in enumerate(order):
        if room_id in messiness:
            rng = stream(seed, "clutter", index)
            clutter = place_room(world, room_id, messiness[room_id], rng, catalogue)
            placed += clutter.placed
            skipped += clutter.skipped
    return Clutter(tuple(placed), tuple(skipped))


def free_spot(world: World, room_id: str, clutter: Clutter, footprint: tuple[float, float],
              rng: np.random.Generator, catalogue: Catalogue | None = None,
              ) -> tuple[float, float] | None:
    """Centre of a free ``w`` (along x) by ``d`` (along y) spot in a cluttered room, or None.

    The spot keeps the catalogue's door keep-out, avatar clearance and passage rules.
    """
    if catalogue is None:
        catalogue = default_catalogue()
    space = room_free_space(world, room_id)
    keepout = door_keepout(space, world.rooms[room_id], catalogue)
    occupancy = Occupancy.empty(space, keepout, catalogue.passage)
    items = catalogue.items.present()
    for item in clutter.in_room(room_id):
        spec = items.get(item.kind)
        occupancy.stamp(space, item.box,
                        spec.clearance if spec else catalogue.avatars.clearance)
    occupancy.settle(space, catalogue.passage)
    spot = place_in(space, occupancy, footprint, rng, clearance=catalogue.avatars.clearance,
                    passage=catalogue.passage, turn=False)
    return None if isinstance(spot, str) else spot.center


def place_in(space: FreeSpace, occupied: Occupancy, footprint: Sequence[float],
             rng: np.random.Generator, *, against_wall: bool = False, clearance: float = 0.0,
             passage: float = 0.7, attempts: int = ATTEMPTS, turn: bool = True) -> Spot | str:
    """Put a ``w x d`` footprint on free floor and stamp it into ``occupied``.

    Returns the spot, or why there is none. ``against_wall`` puts its back (the ``w`` side)
    along the traced boundary; ``turn`` allows a quarter turn of a free-standing footprint.
    """
    w, d = float(footprint[0]), float(footprint[1])
    compiled = kernels()
    if compiled is not None:
        return _place_compiled(compiled, space, occupied, (w, d), against_wall, turn, rng,
                               clearance, passage, attempts)
    candidates = _candidates(space, occupied, w, d, against_wall, clearance, turn)
    if not candidates:
        return _no_spot(w, d, against_wall)
    bounds = list(itertools.accumulate(len(c[1]) for c in candidates))
    total = bounds[-1]
    tries = rng.choice(total, size=min(attempts, total), replace=False)
    for pick in tries.tolist():
        which = bisect.bisect_right(bounds, pick)
        layout, corners, width = candidates[which]
        offset = pick - (bounds[which - 1] if which else 0)
        spot = layout.spot(space, divmod(int(corners[offset]), width))
        if occupied.try_stamp(space, _footprint_box(spot), clearance, passage):
            return spot
    return CUT_OFF


def _no_spot(w: float, d: float, against_wall: bool) -> str:
    where = "along a wall" if against_wall else "on the free floor"
    return f"no {w:.2f} x {d:.2f} m spot {where}"


def _place_compiled(compiled: ModuleType, space: FreeSpace, occupied: Occupancy,
                    footprint: tuple[float, float], against_wall: bool, turn: bool,
                    rng: np.random.Generator, clearance: float, passage: float,
                    attempts: int) -> Spot | str:
    """:func:`place_in` by the compiled kernels: the same spots found in the same order,
    the same draws, the same tries stamped (``occupied`` updated as its ``try_stamp`` does)."""
    layouts = _layouts(*footprint, space.cell, against_wall, turn)
    cells = np.array([(*layout.cells, layout.wall) for layout in layouts])
    corners, counts = compiled.fits(
        space.free, occupied.keepout, occupied.halo, occupied.taken, wall_sides(space),
        math.ceil(clearance / space.cell - 1e-6), cells)
    total = len(corners)
    if total == 0:
        return _no_spot(*footprint, against_wall)
    tries = rng.choice(total, size=min(attempts, total), replace=False)
    kept, reach, walk_eroded = compiled.place(
        space.free, space.open_floor, space.inside, space.door, occupied.taken, occupied.halo,
        occupied.reach, occupied.walk_eroded, corners, counts, cells,
        np.array([layout.extent for layout in layouts]), tries, space.origin, space.cell,
        clearance, disk_rows(passage / 2 / space.cell))
    if kept < 0:
        return CUT_OFF
    occupied.kept_compiled(reach, walk_eroded)
    pick, which = int(tries[kept]), 0
    while pick >= counts[which]:
        pick -= int(counts[which])
        which += 1
    layout = layouts[which]
    return layout.spot(space, divmod(int(corners[tries[kept]]), space.shape[1] - layout.cells[1]
                                     + 1))


@dataclass(frozen=True)
class _Layout:
    """A footprint turned one way: its extent in cells, and the wall it backs onto (or -1)."""

    extent: tuple[float, float]
    cells: tuple[int, int]
    yaw: float
    wall: int  # 0..3: wall towards -x, +x, -y, +y; -1: free-standing

    def spot(self, space: FreeSpace, corner: tuple[Any, Any]) -> Spot:
        i, j = int(corner[0]), int(corner[1])
        (ex, ey), (kx, ky), c = self.extent, self.cells, space.cell
        x0, y0 = space.origin[0] + i * c, space.origin[1] + j * c
        x1, y1 = x0 + kx * c, y0 + ky * c
        cx = {0: x0 + ex / 2, 1: x1 - ex / 2}.get(self.wall, (x0 + x1) / 2)
        cy = {2: y0 + ey / 2, 3: y1 - ey / 2}.get(self.wall, (y0 + y1) / 2)
        return Spot((cx, cy), self.extent, self.yaw)


def _layouts(w: float, d: float, cell: float, against_wall: bool,
             turn: bool) -> list[_Layout]:
    def cells(ex: float, ey: float) -> tuple[int, int]:
        return math.ceil(ex / cell - 1e-6), math.ceil(ey / cell - 1e-6)

    along_x, along_y = (w, d), (d, w)
    if against_wall:  # the depth axis points away from the wall
        return [_Layout(along_y, cells(*along_y), math.pi / 2, side) for side in (0, 1)] + \
            [_Layout(along_x, cells(*along_x), 0.0, side) for side in (2, 3)]
    layouts = [_Layout(along_x, cells(*along_x), 0.0, -1)]
    if turn and w != d:
        layouts.append(_Layout(along_y, cells(*along_y), math.pi / 2, -1))
    return layouts


def _candidates(space: FreeSpace, occupied: Occupancy, w: float, d: float, against_wall: bool,
                clearance: float, turn: bool) -> list[tuple[_Layout, np.ndarray, int]]:
    """Each layout with the lower corner cells where it fits (flat indices into a grid of
    the width given with them)."""
    # a window fits where all its cells are allowed and none is within the clearance of a
    # taken one (the window grown by the clearance holds no taken cell): one table for both
    allowed = space.free & ~occupied.keepout & ~occupied.halo
    allowed &= ~occupied.near_taken(math.ceil(clearance / space.cell - 1e-6))
    allowed_table = summed(allowed)
    found = []
    nx, ny = space.shape
    for layout in _layouts(w, d, space.cell, against_wall, turn):
        kx, ky = layout.cells
        if against_wall and kx <= nx and ky <= ny:  # only the windows along the wall
            corners, (a, b, c, e) = wall_windows(space, layout.wall, kx, ky)
            table = allowed_table.ravel()
            corners = corners[table[a] - table[b] - table[c] + table[e] == kx * ky]
            if len(corners):
                found.append((layout, corners, ny - ky + 1))
            continue
        fits = window(allowed_table, kx, ky) == kx * ky
        if fits.size == 0:
            continue
        corners = np.flatnonzero(fits)  # in the order of np.argwhere, as flat indices
        if len(corners):
            found.append((layout, corners, fits.shape[1]))
    return found


def _footprint_box(spot: Spot) -> Box:
    (cx, cy), (ex, ey) = spot.center, spot.extent
    return Box((cx - ex / 2, cy - ey / 2, 0.0), (cx + ex / 2, cy + ey / 2, 0.0))


def door_keepout(space: FreeSpace, room: Room, catalogue: Catalogue) -> BoolArray:
    """Cells of the rectangle inside the room in front of its door, which stays empty."""
    depth, width = catalogue.door_keepout
    axis, door = room.door.normal_axis, room.door
    inward = 1.0 if room.box.center[axis] > door.center[axis] else -1.0
    face = room.box.lo[axis] if inward > 0 else room.box.hi[axis]
    lo, hi = [0.0, 0.0], [0.0, 0.0]
    lo[axis], hi[axis] = sorted((face, face + inward * depth))
    other = 1 - axis
    lo[other], hi[other] = door.center[other] - width / 2, door.center[other] + width / 2
    mask = np.zeros(space.shape, dtype=bool)
    mask[space.cells(lo, hi)] = True
    return mask


def _size(rng: np.random.Generator, low: tuple[float, float, float],
          high: tuple[float, float, float]) -> tuple[float, float, float]:
    """``rng.uniform(low, high)``'s draw (the same numbers: ``low + (high - low) * u``), without
    its checks of array bounds, which cost more than the draw (once an item)."""
    u = rng.random(3).tolist()
    return (low[0] + (high[0] - low[0]) * u[0], low[1] + (high[1] - low[1]) * u[1],
            low[2] + (high[2] - low[2]) * u[2])


def _count(expected: float) -> int:
    """Round half up: 2.5 items are 3."""
    return math.floor(expected + 0.5)


def _draw_attributes(catalogue: Catalogue,
                     rng: np.random.Generator) -> tuple[tuple[str, object], ...]:
    allowed = catalogue.avatars.attributes
    drawn: dict[str, object] = {}
    for name in type(allowed).model_fields:
        values = getattr(allowed, name)
        drawn[name] = values[int(rng.integers(len(values)))]
    return tuple(agree(drawn).items())
