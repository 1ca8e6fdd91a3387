"""What a run adds to its world: furniture by messiness, avatars (the target among them),
patrolling avatars and moving obstacles.

Furniture is placed per room, lazily and with one generator per room, so that a kinematic
mission only pays for the rooms it looks into and the result never depends on the order in
which rooms are looked at. Whatever moves follows a closed loop at its speed, so its position
is known at any time, in both fidelities.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from astralis_des.kinds import TARGET_HEIGHT
from astralis_des.memo import kept
from astralis_des.streams import stream
from astralis_des.world import coverage as cov
from astralis_des.world.catalogue import Catalogue
from astralis_des.world.clutter import Clutter, Placed, free_spot, furnish
from astralis_des.world.geometry import Box, FloatArray, boxes_array, segments_hit_boxes
from astralis_des.world.model import World

STANDING = (0.5, 0.5)  # m, footprint of a sitting, standing or walking avatar
LAYING = (1.8, 0.6)
PATROL_INSET = 1.0  # m from the walls of a patrolled room
AVATAR_HEIGHTS = {"tall": 1.85, "medium": 1.72, "short": 1.58}


@dataclass(frozen=True)
class Mover:
    """A body going round a closed loop at constant speed: a patrolling avatar or an obstacle."""

    id: str
    kind: str  # avatar | obstacle
    loop: FloatArray  # (N, 3), first point repeated last; the body's centre
    speed: float
    size: tuple[float, float, float]
    offset: float = 0.0  # arc length along the loop at t = 0
    attributes: tuple[tuple[str, Any], ...] = ()
    cum: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        seg = np.linalg.norm(np.diff(self.loop, axis=0), axis=1)
        object.__setattr__(self, "cum", np.concatenate([[0.0], np.cumsum(seg)]))
        # plain lists for one position at a time: asked every tick in physics
        object.__setattr__(self, "_cum", self.cum.tolist())
        object.__setattr__(self, "_points", self.loop.tolist())

    def positions_at(self, times: FloatArray) -> FloatArray:
        s = (self.offset + self.speed * np.asarray(times, dtype=float)) % max(self.cum[-1], 1e-9)
        return np.column_stack([np.interp(s, self.cum, self.loop[:, k]) for k in range(3)])

    def position_at(self, t: float) -> FloatArray:
        cum, points = self._cum, self._points  # type: ignore[attr-defined]
        s = (self.offset + self.speed * t) % max(cum[-1], 1e-9)
        i = min(max(bisect.bisect_right(cum, s) - 1, 0), len(cum) - 2)
        span = cum[i + 1] - cum[i]
        w = (s - cum[i]) / span if span > 0 else 0.0
        a, b = points[i], points[i + 1]
        return np.array([a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1]),
                         a[2] + w * (b[2] - a[2])])


@dataclass(frozen=True)
class Target:
    """The avatar the team searches for; it may patrol its room."""

    room: str
    avatar: dict[str, Any]
    start: tuple[float, float, float]  # centre of the body at t = 0
    mover: Mover | None = None
    size: tuple[float, float, float] = STANDING + (2 * TARGET_HEIGHT,)  # its box, m

    @property
    def position(self) -> tuple[float, float, float]:
        return self.start

    def positions_at(self, times: FloatArray) -> FloatArray:
        if self.mover is None:
            return np.repeat(np.array([self.start]), len(np.atleast_1d(times)), axis=0)
        return self.mover.positions_at(times)

    def position_at(self, t: float) -> FloatArray:
        return self.positions_at(np.array([t]))[0]


@lru_cache(maxsize=8)
def _people_only(catalogue: Catalogue) -> Catalogue:
    """The catalogue without its furniture (kept: a world's furnished-room memo knows a
    catalogue by identity)."""
    return catalogue.model_copy(update={"items": type(catalogue.items)()})


class Scene:
    def __init__(self, world: World, messiness: Mapping[str, float], seed: int,
                 catalogue: Catalogue, *, clutter: bool = True, movers: int = 0,
                 mover_speed: float = 0.6, furnish_outdoors: bool = False,
                 on_skipped: Callable[[str, str, str], None] | None = None) -> None:
        self.world = world
        self.messiness = dict(messiness)
        self.seed = seed
        self.catalogue = catalogue
        # out in the open only bystanders, unless asked: no office chairs on a lawn
        self.outdoors = catalogue if furnish_outdoors else _people_only(catalogue)
        self.enabled = clutter
        self.on_skipped = on_skipped  # told of each item a room had no place for
        # told of each room when it is furnished (the physics adds its bodies then)
        self.listeners: list[Callable[[str, Clutter], None]] = []
        self._order = {rid: i for i, rid in enumerate(sorted(world.rooms))}
        self._rooms: dict[str, Clutter] = {}
        self._still: dict[str, FloatArray] = {}  # room -> boxes of what stays put in it
        self._blocking: dict[tuple[str, ...], FloatArray] = {}  # rooms -> what blocks sight
        self._reserved: dict[str, Box] = {}  # room -> the target's footprint, kept free
        self.target: Target | None = None
        self.movers: list[Mover] = self._corridor_movers(movers, mover_speed)

    # -- clutter ---------------------------------------------------------------------------
    def furnish(self, room_ids: Iterable[str]) -> None:
        """The explicit step that puts furniture and avatars in rooms: each of ``room_ids``
        not furnished yet gets its own (drawn from the seed and the room alone, so when it
        is done does not change what), and the listeners (the physics adds their bodies) and
        ``on_skipped`` are told. Queries (:meth:`clutter`, :meth:`still_boxes`, ...) never
        furnish: they ask about rooms furnished already."""
        for room_id in room_ids:
            if room_id in self._rooms:
                continue
            if not self.enabled:
                self.set_clutter(room_id, Clutter((), ()))
            else:
                indoors = self.world.rooms[room_id].building in self.world.indoors
                placed = furnish(self.world, room_id, self.messiness.get(room_id, 0.0),
                                 self.seed, self._order[room_id],
                                 self.catalogue if indoors else self.outdoors)
                self.set_clutter(room_id, self._clear_target(room_id, placed))
                if self.on_skipped is not None:
                    for skipped in self._rooms[room_id].skipped:
                        self.on_skipped(*skipped)
            for listener in self.listeners:
                listener(room_id, self._rooms[room_id])

    def clutter(self, room_id: str) -> Clutter:
        """A furnished room's furniture and avatars (a ``LookupError`` for a room not
        furnished yet: :meth:`furnish` it first)."""
        try:
            return self._rooms[room_id]
        except KeyError:
            raise LookupError(f"room {room_id} is not furnished yet: Scene.furnish it "
                              "first") from None

    def furnished_rooms(self) -> list[str]:
        """The rooms furnished so far, in order."""
        return sorted(self._rooms)

    def set_clutter(self, room_id: str, clutter: Clutter) -> None:
        """Furnish a room with ``clutter`` (placement, the target's room, tests)."""
        self._rooms[room_id] = clutter
        self._still.pop(room_id, None)
        self._blocking.clear()

    def _clear_target(self, room_id: str, placed: Clutter) -> Clutter:
        keep = self._reserved.get(room_id)
        if keep is None:
            return placed
        blocked = [p for p in placed.placed if _overlap(p.box, keep)]
        return Clutter(tuple(p for p in placed.placed if p not in blocked),
                       placed.skipped + tuple((room_id, p.kind, "moved aside for the target")
                                              for p in blocked))

    def furnish_all(self) -> list[Placed]:
        """Furnish every room (:meth:`furnish`) and give all their furniture and avatars."""
        self.furnish(sorted(self.world.rooms))
        return self.furnished()

    def furnished(self) -> list[Placed]:
        """The furniture and avatars of the rooms furnished so far: in kinematic fidelity the
        rooms the team looked into; in physics, all of them."""
        return [p for rid in sorted(self._rooms) for p in self._rooms[rid].placed]

    def skipped(self) -> list[tuple[str, str, str]]:
        return [s for rid in sorted(self._rooms) for s in self._rooms[rid].skipped]

    def still_boxes(self, room_ids: Iterable[str]) -> FloatArray:
        """``(K, 2, 3)`` corners of what stays put in these rooms: each room's once, kept
        (sight, coverage and planning ask for them again and again)."""
        arrays = []
        for rid in room_ids:
            if rid not in self._still:
                self._still[rid] = _still_of(self.clutter(rid))
            arrays.append(self._still[rid])
        return np.concatenate(arrays) if arrays else np.zeros((0, 2, 3))

    def patrolling(self, room_id: str) -> list[Placed]:
        """The room's patrolling bystanders, in the order ``avatar_movers`` lists them."""
        return [p for p in self.clutter(room_id).placed if _patrols(p)]

    def avatar_movers(self, rooms: Iterable[str] | None = None) -> list[Mover]:
        """Patrolling bystanders of the furnished rooms (or of ``rooms``), as movers, and a
        patrolling target when no rooms are named."""
        found: list[Mover] = []
        for rid in sorted(self._rooms) if rooms is None else rooms:
            found += [self._patrol(f"avatar:{rid}:{i}", rid, p.center, p.size, p.attributes)
                      for i, p in enumerate(self.patrolling(rid))]
        if rooms is None and self.target is not None and self.target.mover is not None:
            found.append(self.target.mover)
        return found

    # -- the target ------------------------------------------------------------------------
    def place_target(self, room_id: str, avatar: dict[str, Any],
                     position: tuple[float, float, float] | None) -> Target:
        """Put the target avatar in its room: at ``position``, or on a free spot."""
        laying = avatar.get("activity") == "laying"
        w, d = LAYING if laying else STANDING
        room = self.world.rooms[room_id]
        floor = room.box.lo[2]
        if position is None:
            rng = stream(self.seed, "target", 1)
            self.furnish([room_id])  # its furniture first: the target finds a free spot
            spot = free_spot(self.world, room_id, self.clutter(room_id), (w, d), rng,
                             self.catalogue)
            if spot is None:  # no free spot left: the room's centre, furniture moved aside
                spot = room.center[:2]
            position = (float(spot[0]), float(spot[1]), floor + TARGET_HEIGHT)
        self._reserved[room_id] = Box((position[0] - w / 2, position[1] - d / 2, floor),
                                      (position[0] + w / 2, position[1] + d / 2, floor + 1.8))
        if room_id in self._rooms:
            self.set_clutter(room_id, self._clear_target(room_id, self._rooms[room_id]))
        mover = None
        if avatar.get("activity") == "patrolling":
            height = AVATAR_HEIGHTS.get(str(avatar.get("height")), 1.72)
            # its box stands on the floor (centred at half its height, not at TARGET_HEIGHT:
            # a tall walker's box reached down through the slab, seen from the floor below)
            centre = (position[0], position[1], floor + height / 2)
            mover = self._patrol("target", room_id, centre, (w, d, height),
                                 tuple(avatar.items()))
        size = mover.size if mover is not None else (w, d, 2 * TARGET_HEIGHT)
        self.target = Target(room_id, dict(avatar), position, mover,
                             tuple(float(v) for v in size))  # type: ignore[arg-type]
        return self.target

    def _patrol(self, ident: str, room_id: str, where: tuple[float, ...],
                size: tuple[float, float, float], attributes: tuple[tuple[str, Any], ...]) -> Mover:
        room = self.world.rooms[room_id]
        ring = cov.within(cov.loop(room.box, PATROL_INSET), room.outline, PATROL_INSET)
        loop = np.column_stack([ring, np.full(len(ring), where[2])])
        mover = Mover(ident, "avatar", loop, 1.0, size, attributes=attributes)
        nearest = int(np.argmin(np.linalg.norm(loop[:, :2] - np.array(where[:2]), axis=1)))
        return Mover(ident, "avatar", loop, 1.0, size, float(mover.cum[nearest]), attributes)

    # -- moving obstacles ------------------------------------------------------------------
    def _corridor_movers(self, count: int, speed: float) -> list[Mover]:
        rng = stream(self.seed, "movers")
        corridors = sorted(s for s, sp in self.world.spaces.items() if sp.kind == "corridor")
        movers = []
        for i in range(count):
            box = self.world.spaces[corridors[int(rng.integers(len(corridors)))]].box
            y = (box.lo[1] + box.hi[1]) / 2
            x0, x1 = sorted(rng.uniform(box.lo[0] + 0.5, box.hi[0] - 0.5, size=2))
            z = box.lo[2] + 0.5
            loop = np.array([[x0, y, z], [x1, y, z], [x0, y, z]])
            movers.append(Mover(f"obstacle:{i}", "obstacle", loop, speed * rng.uniform(0.7, 1.3),
                                (0.5, 0.5, 1.0), float(rng.uniform(0, 2 * (x1 - x0)))))
        return movers

    # -- sight -----------------------------------------------------------------------------
    def blockers(self, rooms: Iterable[str]) -> FloatArray:
        """Boxes that block sight: walls, slabs, obstacles, and the furniture and avatars that
        stay put in ``rooms`` (the target excluded)."""
        key = tuple(rooms)
        found = self._blocking.get(key)
        if found is None:  # kept until a room's clutter changes (sight asks again and again)
            extra = self.still_boxes(key)
            found = self.world.solid_array
            if len(extra):
                found = np.concatenate([found, extra])
                found.setflags(write=False)
            self._blocking[key] = found
        return found

    def line_of_sight(self, p0: FloatArray, p1: FloatArray,
                      rooms: list[str] | None = None) -> np.ndarray:
        """True where nothing lies between ``p0[m]`` and ``p1[m]``. Only the furniture of the
        rooms the segments start or end in can matter: to reach into any other room a
        segment passes through a wall, which blocks it already. Those rooms (``rooms``, where
        the caller has them already: :meth:`rooms_at` of the ends) must be furnished."""
        p0, p1 = np.atleast_2d(p0), np.atleast_2d(p1)
        if rooms is None:
            rooms = self.rooms_at(np.concatenate([p0, p1]))
        return ~segments_hit_boxes(p0, p1, self.blockers(rooms))

    def rooms_at(self, points: FloatArray) -> list[str]:
        """The rooms any of ``points`` lies in, in the world's order."""
        ids = self.world.room_ids
        return [ids[k] for k in self.world.rooms_holding(points).tolist()]


def _overlap(a: Box, b: Box) -> bool:
    return all(a.lo[k] < b.hi[k] and b.lo[k] < a.hi[k] for k in range(2))


def _patrols(placed: Placed) -> bool:
    """A patrolling bystander (a mover), not furniture or an avatar that stays put."""
    return dict(placed.attributes).get("activity") == "patrolling"


def _still_of(clutter: Clutter) -> FloatArray:
    """The corners of what stays put of ``clutter`` (not the patrolling avatars), kept on it
    read-only: a room's furniture is drawn once per world, seed and room, and each run's
    scene asks for its boxes again."""
    memo = kept(clutter, "still_boxes")
    if "boxes" not in memo:
        boxes = boxes_array([p.box for p in clutter.placed if not _patrols(p)])
        boxes.setflags(write=False)
        memo["boxes"] = boxes
    return memo["boxes"]
