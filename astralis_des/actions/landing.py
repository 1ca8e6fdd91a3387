"""Landing: where a UAV comes down, and the way there.

A UAV lands where there is floor under it (not the stairwell's or the lift's open well) and
the square of floor under it is free of walls, furniture, the target, other robots and the
loops that walkers (avatars, moving obstacles) go round; a walker would walk into a UAV
standing on its loop and tip it over. It looks first on rings around it (the usual case),
then on a fine grid over its room (a room whose walkers' loop leaves only a strip free), then
round its room's door (the corridor), and flies to the spot it finds in a straight line its
body clears, else by a route.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from astralis_des.actions.common import StepGen, climb, route, traverse
from astralis_des.kernel.contracts import Context
from astralis_des.kernel.robot import Robot
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.world.geometry import FloatArray
from astralis_des.world.model import Room

log = logging.getLogger(__name__)

LANDING_CLEAR = 0.45  # m: half the side of the square of floor a landing UAV needs free
LANDING_RINGS = (0.0, 0.6, 1.2, 1.8, 2.4)  # m around a UAV where it looks for that square
LANDING_GRID = 0.1  # m between the spots of the finer search when no ring has one
LANDING_FAR = 4.0  # m around a UAV outside any room (or its room's door) where the
# finer search looks
IN_LINE = 400  # the nearest free spots of the finer search tried in a straight line
ROUTED = 3  # the nearest free spots of the finer search tried by a route, if none is in line
ROBOT_ROOM = 0.7  # m: half the side of the square another robot takes (the Husky turning)
DOOR_KEEP = 1.0  # m from a doorway's centre where the finer search lands no UAV
BODY_FOOT = 0.3  # m: half the side of the square a landed UAV stands on (its radius)
SUPPORT_Z = 0.05  # m: a slab's top this near a floor's level carries what lands there
BODY_CLEAR = 0.4  # m: half the side of the square a UAV sweeps flying to its spot
BODY_BAND = 0.15  # m above and below its height that it sweeps


def landing_way(ctx: Context, robot: Robot) -> FloatArray:
    """The points a UAV flies, level, to above where it comes straight down: its own spot,
    or the nearest free one (see the module's notes). Where none is free it stays where it
    is (and says so in the log)."""
    here = robot.position(ctx.env.now)
    floor = ctx.world.floor_below(here)
    room = ctx.world.room_at((here[0], here[1], floor + 0.5))
    rooms = [room.id] if room is not None else []
    scene = ctx.sensor.scene
    scene.furnish(rooms)  # the room it lands in, with its furniture
    taken = _taken(ctx, robot, here, rooms)
    solid = scene.blockers(rooms)
    rings = _rings(here)
    # the cheap tests of every spot on the rings at once, the rest one spot at a time in order
    ok = _free(taken, rings, floor)
    ok[ok] = _supported(ctx, rings[ok], floor)
    for k in np.flatnonzero(ok):
        spot = rings[k]
        if k == 0:
            return here[None, :]
        if _in(ctx, spot, floor, room) and bool(scene.line_of_sight(here, spot)[0]) \
                and _clears(solid, here, spot):
            return np.vstack([here, spot])
    for centre, around, far in _searched(here, room):  # the corridor's grid only if needed
        grid = _grid(ctx, here, centre, floor, around, far)
        spots = grid.spots[_free_on(taken, grid, floor)]
        spots = spots[~ctx.world.near_doorway(spots, floor, DOOR_KEEP)]
        spots = spots[_supported(ctx, spots, floor)]
        way = _nearest_way(ctx, robot, here, spots, solid)
        if way is not None:
            return way
    log.warning("%s: no free spot to land on near %s: it comes down where it is", robot.id,
                np.round(here, 2).tolist())
    return here[None, :]


def _ring_offsets() -> FloatArray:
    """``(49, 3)``: the spots on ``LANDING_RINGS`` around the origin, nearest ring first."""
    offsets = []
    for reach in LANDING_RINGS:
        angles = np.linspace(0.0, 2 * np.pi, 1 if reach == 0 else 12, endpoint=False)
        offsets += [reach * np.array([np.cos(angle), np.sin(angle), 0.0]) for angle in angles]
    return np.array(offsets)


RING_OFFSETS = _ring_offsets()


def _rings(here: FloatArray) -> FloatArray:
    """The spots on ``LANDING_RINGS`` around ``here``, nearest ring first (``here`` first)."""
    return here + RING_OFFSETS


def _nearest_way(ctx: Context, robot: Robot, here: FloatArray, spots: FloatArray,
                 solid: FloatArray) -> FloatArray | None:
    """The way to the nearest of the free ``spots`` reached in a straight line (of the
    ``IN_LINE`` nearest), else by a route to one of the ``ROUTED`` nearest; None if
    neither."""
    spots = spots[np.argsort(np.linalg.norm(spots[:, :2] - here[:2], axis=1), kind="stable")]
    first = _first_clear(solid, here, spots[:IN_LINE])
    if first is not None:
        return np.vstack([here, spots[first]])
    for spot in spots[:ROUTED]:
        way = route(ctx, robot, ctx.world.on_floor(spot))
        if way.points is not None:
            return way.points
    return None


def _taken(ctx: Context, robot: Robot, here: FloatArray, rooms: list[str]) -> FloatArray:
    """``(K, 2, 3)`` boxes a landing UAV keeps off: walls, furniture, people who stay put,
    the target, the loops walkers go round, and the other robots (a UGV under it in a
    corridor)."""
    scene = ctx.sensor.scene
    scene.furnish(rooms)
    boxes = scene.blockers(rooms)
    walks = [*scene.movers, *scene.avatar_movers(rooms)]
    target = scene.target
    if target is not None and target.mover is not None:
        walks.append(target.mover)
    elif target is not None:  # nor on the person found (still there)
        half = np.asarray(target.size) / 2
        boxes = np.concatenate([boxes, np.array([[np.subtract(target.start, half),
                                                  np.add(target.start, half)]])])
    if walks:  # nor on the loop a walker or an obstacle goes round
        kept = ctx.world.memo("walk_boxes", 1024)  # the same loops at every landing
        boxes = np.concatenate([boxes, *[_walked(kept, m.loop, m.size) for m in walks]])
    others = [r.position(ctx.env.now) for r in ctx.robots.values() if r is not robot]
    if others:
        at = np.array(others)
        lo = np.column_stack([at[:, :2] - ROBOT_ROOM, np.full(len(at), -1e3)])
        hi = np.column_stack([at[:, :2] + ROBOT_ROOM, at[:, 2] + 0.5])
        boxes = np.concatenate([boxes, np.stack([lo, hi], axis=1)])
    return boxes


def _free(boxes: FloatArray, spots: FloatArray, floor: float) -> np.ndarray:
    """Where the square of floor under each spot (up to the spot) meets none of ``boxes``."""
    if not len(spots):
        return np.zeros(0, dtype=bool)
    lo = np.column_stack([spots[:, :2] - LANDING_CLEAR, np.full(len(spots), floor + 0.02)])
    hi = np.column_stack([spots[:, :2] + LANDING_CLEAR, spots[:, 2]])
    boxes = boxes[np.all((boxes[:, 0] < hi.max(axis=0)) & (boxes[:, 1] > lo.min(axis=0)),
                         axis=1)]
    ok = np.ones(len(spots), dtype=bool)
    for start in range(0, len(spots), 128):  # in blocks of nearby spots (a grid's, a ring's),
        a, b = lo[start:start + 128], hi[start:start + 128]  # each against the boxes near it
        near = boxes[np.all((boxes[:, 0] < b.max(axis=0)) & (boxes[:, 1] > a.min(axis=0)),
                            axis=1)]
        hit = np.all((near[None, :, 0] < b[:, None]) & (near[None, :, 1] > a[:, None]), axis=2)
        ok[start:start + 128] = ~hit.any(axis=1)
    return ok


def _supported(ctx: Context, spots: FloatArray, floor: float) -> np.ndarray:
    """Where there is floor under a spot: the ground, or the top of a slab at ``floor`` under
    the middle and the corners of the body (not the stairwell's or the lift's open well)."""
    ok = np.ones(len(spots), dtype=bool)
    if floor <= SUPPORT_Z or not len(spots):
        return ok
    solid = ctx.world.solid_array
    tops = solid[np.abs(solid[:, 1, 2] - floor) < SUPPORT_Z]
    for dx, dy in ((0.0, 0.0), (-1, -1), (-1, 1), (1, -1), (1, 1)):
        at = spots[:, :2] + np.array([dx, dy]) * BODY_FOOT
        ok &= np.any(np.all((at[:, None, :] >= tops[None, :, 0, :2]) &
                            (at[:, None, :] <= tops[None, :, 1, :2]), axis=2), axis=1)
    return ok


def _in(ctx: Context, spot: FloatArray, floor: float, room: Room | None) -> bool:
    """Is ``spot`` over the same floor, in the same room (or in none, as ``room``)?"""
    if abs(ctx.world.floor_below(spot) - floor) > 0.05:
        return False
    there = ctx.world.room_at((spot[0], spot[1], floor + 0.5))
    return (there.id if there else None) == (room.id if room else None)


def _searched(here: FloatArray, room: Room | None
              ) -> list[tuple[FloatArray, Room | None, float]]:
    """Where the finer search looks, in turn: over the UAV's room, then round its door (the
    corridor); outside any room, near it and then farther (over the stair hall's well)."""
    if room is None:
        return [(here, None, LANDING_FAR), (here, None, 2 * LANDING_FAR)]
    door = np.array([*room.door.center[:2], here[2]])
    return [(here, room, LANDING_FAR), (door, None, LANDING_FAR)]


@dataclass(frozen=True)
class _Grid:
    """Spots ``LANDING_GRID`` apart at height ``z``: the grid ``xs`` by ``ys`` (``[i, j]``
    raveled), those of ``where`` only (all if None)."""

    xs: FloatArray
    ys: FloatArray
    z: float
    where: np.ndarray | None

    @property
    def spots(self) -> FloatArray:
        gx, gy = np.meshgrid(self.xs, self.ys, indexing="ij")
        spots = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, self.z)])
        return spots if self.where is None else spots[self.where]


def _grid(ctx: Context, here: FloatArray, centre: FloatArray, floor: float,
          room: Room | None, far: float = LANDING_FAR) -> _Grid:
    """Spots ``LANDING_GRID`` apart at ``here``'s height: over the room, else within
    ``far`` of ``centre``, outside every room and over the same floor."""
    if room is not None:
        lo = np.asarray(room.box.lo[:2], dtype=float) + LANDING_CLEAR
        hi = np.asarray(room.box.hi[:2], dtype=float) - LANDING_CLEAR
    else:
        lo, hi = centre[:2] - far, centre[:2] + far
    xs = np.arange(lo[0], hi[0] + 1e-9, LANDING_GRID)
    ys = np.arange(lo[1], hi[1] + 1e-9, LANDING_GRID)
    if room is not None:
        return _Grid(xs, ys, float(here[2]), None)
    boxes = ctx.world.room_boxes
    level = floor + 0.5
    inside = np.zeros((len(xs), len(ys)), dtype=bool)
    for k in np.flatnonzero(np.all((boxes[:, 0, :2] <= hi) & (boxes[:, 1, :2] >= lo), axis=1)):
        if boxes[k, 0, 2] <= level <= boxes[k, 1, 2]:  # a box test, an axis at a time
            inside |= np.outer((xs >= boxes[k, 0, 0]) & (xs <= boxes[k, 1, 0]),
                               (ys >= boxes[k, 0, 1]) & (ys <= boxes[k, 1, 1]))
    where = ~inside.ravel()
    grid = _Grid(xs, ys, float(here[2]), where)
    if where.any():
        where[where] = np.abs(ctx.world.floors_below(grid.spots) - floor) < 0.05
    return grid


def _free_on(boxes: FloatArray, grid: _Grid, floor: float) -> np.ndarray:
    """:func:`_free` of the grid's spots: the spots whose square a box meets are those of a
    range of columns (x) and rows (y), at the grid's height; the ranges are counted on the
    grid at once (a table of differences, summed)."""
    xs, ys = grid.xs, grid.ys
    boxes = boxes[(boxes[:, 0, 2] < grid.z) & (boxes[:, 1, 2] > floor + 0.02)]
    # the spots whose lo < a box's hi and whose hi > its lo, an axis at a time: the spots'
    # bounds grow with their index, so these are the ranges searchsorted finds
    i0 = np.searchsorted(xs + LANDING_CLEAR, boxes[:, 0, 0], side="right")
    i1 = np.searchsorted(xs - LANDING_CLEAR, boxes[:, 1, 0], side="left")
    j0 = np.searchsorted(ys + LANDING_CLEAR, boxes[:, 0, 1], side="right")
    j1 = np.searchsorted(ys - LANDING_CLEAR, boxes[:, 1, 1], side="left")
    some = (i0 < i1) & (j0 < j1)
    i0, i1, j0, j1 = i0[some], i1[some], j0[some], j1[some]
    counts = np.zeros((len(xs) + 1, len(ys) + 1), dtype=np.int64)
    for rows, cols, step in ((i0, j0, 1), (i0, j1, -1), (i1, j0, -1), (i1, j1, 1)):
        np.add.at(counts, (rows, cols), step)
    hit = np.cumsum(np.cumsum(counts, axis=0), axis=1)[:-1, :-1] > 0
    free = ~hit.ravel()
    return free if grid.where is None else free[grid.where]


def _clears(solid: FloatArray, here: FloatArray, spot: FloatArray) -> bool:
    """Does a UAV flying level from ``here`` to ``spot`` keep its square clear of ``solid``
    (walls, door jambs, furniture) all the way?"""
    steps = _steps(here, spot)
    pts = here + np.outer(np.linspace(0.0, 1.0, steps + 1), spot - here)
    lo = np.column_stack([pts[:, :2] - BODY_CLEAR, pts[:, 2] - BODY_BAND])
    hi = np.column_stack([pts[:, :2] + BODY_CLEAR, pts[:, 2] + BODY_BAND])
    near = np.all((solid[:, 0] < hi.max(axis=0)) & (solid[:, 1] > lo.min(axis=0)), axis=1)
    boxes = solid[near]
    hit = np.all((boxes[None, :, 0] < hi[:, None]) & (boxes[None, :, 1] > lo[:, None]), axis=2)
    return not bool(hit.any())


def _first_clear(solid: FloatArray, here: FloatArray, spots: FloatArray,
                 block: int = 32) -> int | None:
    """The first of ``spots`` that :func:`_clears` (the same test, ``block`` spots at a
    time), or None."""
    for start in range(0, len(spots), block):
        part = spots[start:start + block]
        steps = _steps_of(here, part)
        # each spot's points, as np.linspace(0, 1, steps + 1) places them
        which = np.repeat(np.arange(len(part)), steps + 1)
        first = np.concatenate([[0], np.cumsum(steps + 1)[:-1]])
        k = np.arange(len(which)) - first[which]
        t = k * (1.0 / steps[which])
        t[first[1:] - 1] = 1.0
        t[-1] = 1.0
        pts = here + t[:, None] * (part - here)[which]
        lo = np.column_stack([pts[:, :2] - BODY_CLEAR, pts[:, 2] - BODY_BAND])
        hi = np.column_stack([pts[:, :2] + BODY_CLEAR, pts[:, 2] + BODY_BAND])
        near = np.all((solid[:, 0] < hi.max(axis=0)) & (solid[:, 1] > lo.min(axis=0)), axis=1)
        boxes = solid[near]
        hit = np.all((boxes[None, :, 0] < hi[:, None]) & (boxes[None, :, 1] > lo[:, None]),
                     axis=2).any(axis=1)
        clear = np.flatnonzero(np.bincount(which, weights=hit, minlength=len(part)) == 0)
        if len(clear):
            return start + int(clear[0])
    return None


def _steps(here: FloatArray, spot: FloatArray) -> int:
    d = spot - here  # np.linalg.norm's sum for a vector, without its overhead
    return max(math.ceil(math.sqrt(float(d.dot(d))) / 0.1), 1)


def _steps_of(here: FloatArray, spots: FloatArray) -> np.ndarray:
    """:func:`_steps` of each of ``spots``: at once, and one at a time where a distance is so
    near a whole number of steps that the rounding of the norm could change the count."""
    tenths = np.sqrt(((spots - here) ** 2).sum(axis=1)) / 0.1
    steps = np.maximum(np.ceil(tenths), 1).astype(np.intp)
    for k in np.flatnonzero(np.abs(tenths - np.round(tenths)) < 1e-6):
        steps[k] = _steps(here, spots[k])
    return steps


def _walked(kept: dict[Any, FloatArray], loop: FloatArray,
            size: tuple[float, float, float]) -> FloatArray:
    """:func:`_along`, ``kept`` by loop and size (read-only)."""
    key = (loop.tobytes(), loop.shape, tuple(size))
    if key not in kept:
        kept[key] = _along(loop, size)
        kept[key].flags.writeable = False
    return kept[key]


def _along(loop: FloatArray, size: tuple[float, float, float]) -> FloatArray:
    """``(K, 2, 3)`` boxes of a body of ``size`` every 0.2 m along its ``loop``."""
    legs = np.diff(loop, axis=0)
    steps = np.maximum(np.ceil(np.linalg.norm(legs, axis=1) / 0.2).astype(int), 1)
    pts = np.vstack([a + np.outer(np.arange(n) / n, leg)
                     for a, leg, n in zip(loop[:-1], legs, steps, strict=True)])
    half = np.asarray(size) / 2
    return np.stack([pts - half, pts + half], axis=1)


def land(ctx: Context, robot: Robot) -> StepGen:
    """A flying UAV comes straight down onto the floor (a ``landed`` event): under it, or
    beside it where the floor under it is taken (:func:`landing_way`)."""
    rest = KIND_DEFAULTS[robot.kind].rest
    if not robot.airborne or rest is None:
        return 0.0
    way = landing_way(ctx, robot)
    distance = 0.0
    if len(way) > 1:
        distance = yield from traverse(ctx, robot, way, sense=False)
    robot.airborne = False  # from here on it is coming down (stopped, it takes off again)
    distance += yield from climb(ctx, robot, rest)
    ctx.log.emit("landed", robot.id, position=[round(float(v), 3)
                                               for v in robot.position(ctx.env.now)])
    return distance
