"""Routes for one simulation: the room graph finds the way (doors, corridors, stairwells), and
in ``map`` mode every leg a straight line cannot take is planned around what stands in it, by
the planner the robot's kind names (:mod:`astralis_des.planning.planners`): OMPL in 3-D for a
UAV, OMPL in SE2 (Reeds-Shepp) for the UGV, A* on the floor for a walker.

``graph`` mode (the kinematic default) keeps the graph's straight legs: thousands of missions
a minute. ``map`` mode (the physics default) follows each room's real furniture.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from astralis_des.errors import InputError
from astralis_des.kinds import KIND_DEFAULTS, KindDefaults
from astralis_des.memo import kept
from astralis_des.planning.footprint import RIM, fits_turned
from astralis_des.planning.lintels import Lintels
from astralis_des.planning.planners import PLANNERS, Leg, Planned
from astralis_des.world.geometry import FloatArray, segments_hit_boxes

if TYPE_CHECKING:
    from astralis_des.mission.spec import MissionSpec
    from astralis_des.planning.occupancy import GridMap, VoxelMap
    from astralis_des.world.model import World
    from astralis_des.world.scene import Scene

WINDOW = 3.0  # m around a leg that its planner may use
NUDGE = 0.6  # m: how far a leg's end in collision may be moved to a free point
CELL = 0.1  # m, walkers' floor grid
LIFT_SLACK = 0.05  # m above the clearance a UAV's point lifted over furniture is put


@dataclass(frozen=True)
class Route:
    points: FloatArray | None  # at the robot's sensor height; None when there is none
    reason: str = ""
    skipped: int = 0  # points left out as unreachable (``refine(..., skip=True)``)


class Robot(Protocol):
    """What routing needs of a robot (the kernel's robots are such)."""

    kind: str  # uav, ugv or human: what it may use (stairs, ramps, the lift) and its body
    height: float  # m above the floor of its sensor: where its route runs


class Navigator(Lintels):
    def __init__(self, world: World, scene: Scene, spec: MissionSpec) -> None:
        self.world, self.scene, self.cfg = world, scene, spec.planning
        method = self.cfg.method
        self.method = method if method != "auto" else (
            "map" if spec.fidelity == "physics" else "graph")
        self.seed = spec.seed
        self.seconds = 0.0  # wall time spent planning
        self.plans = 0
        self._counter = itertools.count()
        self._map: VoxelMap | None = None

    # -- the way ---------------------------------------------------------------------------
    def route(self, robot: Robot, start: FloatArray, goal: FloatArray,
              at: FloatArray | None = None) -> Route:
        """From ``start`` to ``goal`` (both at floor level) for this robot. ``at``: where the
        robot is; if above its sensor height over ``start`` (a UAV over the furniture it
        searched from), the route leaves from there, level, and comes down past it."""
        t0 = time.perf_counter()
        try:
            try:
                way = self.world.router.route(start, goal, robot.kind)
            except InputError as exc:  # a goal in a wall or off the site, asked at run time
                return Route(None, exc.message)
            if way is None:
                return Route(None, f"no way for a {robot.kind} to there")
            points = way + np.array([0.0, 0.0, robot.height])
            if len(self.world.block_array):
                from astralis_des.planning.blocks import round_blocks

                rounded, reason = round_blocks(
                    self.world, points, _kind(robot).radius + self.cfg.margin,
                    fly=_kind(robot).flies, floor=float(start[2]))
                if rounded is None:
                    return Route(None, reason)
                points = rounded
            if at is not None and float(at[2] - points[0][2]) > LIFT_SLACK:
                # the first leg only: the others may climb a stairwell, on the graph's slant
                first = level_legs(np.vstack([at, points[1:2]]))
                points = np.vstack([first[:-1] if len(points) > 1 else first, points[1:]])
            if self.method == "graph":
                return Route(self._ducked(robot, points, _kind(robot).radius +
                                          self.cfg.margin) if _kind(robot).flies else points)
            return self.refine(robot, points)
        finally:
            self.seconds += time.perf_counter() - t0

    def refine(self, robot: Robot, points: FloatArray, skip: bool = False) -> Route:
        """Replace each leg a straight line cannot take by a planned detour. With ``skip``
        (a coverage path) a point no detour reaches is left out and counted, and the path
        goes on to the next one; else the route fails there."""
        radius = _kind(robot).radius + self.cfg.margin
        if _kind(robot).flies:
            points = self._under_lintels(robot, points, radius)
        out = [points[0]]
        skipped = 0
        for b in points[1:]:
            a = out[-1]
            if float(np.linalg.norm(b - a)) < 1e-9 or self._leg_free(robot, a, b, radius):
                out.append(b)
                continue
            ducked = self._duck(robot, a, b, self._free(np.array([a, b]), radius,
                                                         _kind(robot).keep_out)) \
                if _kind(robot).flies else None
            if ducked is not None:
                out.extend(ducked[1:])
                continue
            detour, reason = self._plan_leg(robot, a, b, radius)
            if detour is None:
                if skip:
                    skipped += 1
                    continue
                where = ", ".join(f"{v:.1f}" for v in b)
                return Route(None, f"no path to [{where}]: {reason}")
            out.extend(detour[1:])
        return Route(np.array(out), skipped=skipped)

    def usable(self, robot: Robot, points: FloatArray) -> Route:
        """The points of a coverage path the robot's body fits at (the others dropped and
        counted in ``skipped``), the same whichever way the robot plans, so that a search
        reports the same coverage in both. A walker's and the UGV's are checked on their
        floor's grid (cheap). A UAV's point over furniture or a person is lifted clear of it
        (a pilot flies over a cabinet rather than leave a corner of the room unseen) when the
        ceiling leaves room, else dropped; the map (``map`` mode only: on the graph none is
        built) checks the walls. :func:`level_legs` then makes its legs climb and come down
        clear of what it flies over."""
        if _kind(robot).flies:
            points, ok = self._over_furniture(robot, np.atleast_2d(points))
            if self.method == "map":
                ok &= self.fits(robot, points)
        else:
            ok = self.fits(robot, points)
        return Route(points[ok], skipped=int((~ok).sum()))

    def _over_furniture(self, robot: Robot, points: FloatArray) -> tuple[FloatArray, np.ndarray]:
        """``points`` each raised above the still furniture and people it would touch (boxes
        grown by the body, its margin and its kind's ``keep_out``), and where the raised point keeps
        that clearance below its room's ceiling."""
        pts = np.array(points, dtype=float)
        clear = _kind(robot).radius + self.cfg.margin + _kind(robot).keep_out
        boxes = self.furniture(pts.min(axis=0) - clear, pts.max(axis=0) + clear)
        ok = np.ones(len(pts), dtype=bool)
        if not len(boxes):
            return pts, ok
        lo, hi = boxes[:, 0] - clear, boxes[:, 1] + clear
        under = np.all((pts[:, None, :2] >= lo[None, :, :2]) &
                       (pts[:, None, :2] <= hi[None, :, :2]), axis=2)  # (N, K)
        for i in np.flatnonzero((under & (lo[None, :, 2] <= pts[:, None, 2]) &
                                 (hi[None, :, 2] >= pts[:, None, 2])).any(axis=1)):
            top = float(hi[under[i], 2].max()) + LIFT_SLACK
            room = self.world.room_at(pts[i])
            ceiling = (room.box.hi[2] if room is not None else
                       self.world.floor_below(pts[i]) + robot.height + clear) - clear
            pts[i, 2] = top
            ok[i] = top <= ceiling
        return pts, ok

    def fits(self, robot: Robot, points: FloatArray) -> np.ndarray:
        """Where (``points`` at its sensor height) the robot's body is clear, by the check its
        planner uses: a UAV's in the voxel map with the furniture, a walker's and the UGV's
        on the grid of their floor's slice."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        radius = _kind(robot).radius + self.cfg.margin
        if _kind(robot).flies:
            return np.asarray(self._valid(robot, pts, radius))
        ok = np.zeros(len(pts), dtype=bool)
        floors = np.array([self.world.floor_below(p - np.array([0.0, 0.0, robot.height]))
                           for p in pts])
        for floor in np.unique(floors):
            mine = floors == floor
            lo = pts[mine, :2].min(axis=0) - radius - 2 * CELL
            hi = pts[mine, :2].max(axis=0) + radius + 2 * CELL
            ok[mine] = self.floor_grid(lo, hi, float(floor)).free(pts[mine, :2], radius)
        return ok

    def stands(self, robot: Robot, points: FloatArray) -> np.ndarray:
        """Where the robot can stand and set off from: it fits (:meth:`fits`), and a long
        body's rectangle (the Husky's) fits at some heading, as its planner needs of a start
        or a goal."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        ok = self.fits(robot, pts)
        footprint = _kind(robot).footprint
        if footprint is None or not ok.any():
            return ok
        reach = (_kind(robot).swept_radius or 0.0) + self.rim_clearance + 2 * CELL
        at = np.flatnonzero(ok)
        floors = np.array([self.world.floor_below(p - np.array([0.0, 0.0, robot.height]))
                           for p in pts[at]])
        for floor in np.unique(floors):  # one grid a floor (it is on the world's lattice)
            mine = at[floors == floor]
            grid = self.floor_grid(pts[mine, :2].min(axis=0) - reach,
                                    pts[mine, :2].max(axis=0) + reach, float(floor))
            ok[mine] = fits_turned(grid, pts[mine], footprint, self.rim_clearance)
        return ok

    @property
    def rim_clearance(self) -> float:
        """What a long body's rim keeps from what stands on the floor (the grid's cells are
        checked at the rim's points, ``RIM`` apart)."""
        return self.cfg.margin + RIM / 2

    def prepare(self) -> None:
        """Build the planner's map now rather than on the first route (a server does, so
        that no request waits for it)."""
        if self.method == "map":
            _ = self.map

    # -- what is in the way ----------------------------------------------------------------
    @property
    def map_built(self) -> bool:
        return self._map is not None

    def occupied_points(self) -> FloatArray:
        """Centres of the map's occupied voxels above the ground (once per world)."""
        voxels = self.map
        cache: dict[str, FloatArray] = kept(voxels, "occupied_points")
        if "above" not in cache:
            cache["above"] = voxels.center_of(voxels.occupied_cells(above=0.05))
        return cache["above"]

    @property
    def map(self) -> VoxelMap:
        if self._map is None:
            from astralis_des.planning.occupancy import world_map

            self._map = world_map(self.world)
        return self._map

    def furniture(self, lo: FloatArray, hi: FloatArray) -> FloatArray:
        """Boxes of still furniture and avatars in the rooms overlapping ``[lo, hi]``: those
        rooms are furnished first (a plan past a room sees its furniture, whether or not
        anyone has looked in yet)."""
        boxes, ids = self.world.room_boxes, self.world.room_ids
        rooms = [ids[k] for k in np.flatnonzero(np.all((boxes[:, 0] <= hi) &
                                                       (boxes[:, 1] >= lo), axis=1))]
        self.scene.furnish(rooms)
        return self.scene.still_boxes(rooms)

    def _valid(self, robot: Robot, points: FloatArray, radius: float) -> np.ndarray:
        pts = np.atleast_2d(points)
        reach = radius + _kind(robot).keep_out
        boxes = self.furniture(pts.min(axis=0) - reach, pts.max(axis=0) + reach)
        return self.checker(boxes, radius, _kind(robot).keep_out)(pts)

    def checker(self, boxes: FloatArray, radius: float,
                keep_out: float = 0.0) -> Callable[[FloatArray], np.ndarray]:
        """A validity test for many states: the map's clearance, and the furniture ``boxes``
        grown by ``radius`` and ``keep_out`` (gathered once, not per state: a planner asks
        thousands)."""
        voxels = self.map
        grown_lo, grown_hi = boxes[:, 0] - radius - keep_out, boxes[:, 1] + radius + keep_out

        def valid(points: FloatArray) -> np.ndarray:
            pts = np.atleast_2d(points)
            ok = voxels.free(pts, radius)
            if len(grown_lo) and ok.any():
                inside = np.all((pts[:, None, :] >= grown_lo[None]) &
                                (pts[:, None, :] <= grown_hi[None]), axis=2).any(axis=1)
                ok &= ~inside
            return np.asarray(ok)

        return valid

    def _leg_free(self, robot: Robot, a: FloatArray, b: FloatArray, radius: float,
                  furniture: bool = True) -> bool:
        """Is the straight leg clear of every box grown by ``radius`` (walls and slabs only,
        without ``furniture``)? Boxes, not the map: most legs are clear, and the map is then
        never needed (it is built for planning only)."""
        a, b = a.copy(), b.copy()
        if not _kind(robot).flies:  # a ground body stands on its floor: test at its middle
            a[2] = b[2] = self.world.floor_below(a) + 0.4
        keep_out = _kind(robot).keep_out
        lo, hi = np.minimum(a, b) - radius - keep_out, np.maximum(a, b) + radius + keep_out
        things = self.furniture(lo, hi) if furniture else np.zeros((0, 2, 3))
        margins = np.concatenate([np.full(len(self.world.solid_array), radius),
                                  np.full(len(things), radius + keep_out)])
        boxes = np.concatenate([self.world.solid_array, things])
        near = np.all((boxes[:, 0] <= hi) & (boxes[:, 1] >= lo), axis=1)
        boxes, margins = boxes[near], margins[near]
        grown = np.stack([boxes[:, 0] - margins[:, None], boxes[:, 1] + margins[:, None]], axis=1)
        return not bool(segments_hit_boxes(a[None, :], b[None, :], grown)[0])

    # -- planning a leg --------------------------------------------------------------------
    def _plan_leg(self, robot: Robot, a: FloatArray, b: FloatArray,
                  radius: float) -> tuple[FloatArray | None, str]:
        """A detour from ``a`` to ``b``. An end the planner finds in collision (a robot
        stands closer to furniture than its margins allow, a goal beside a person) is moved
        to the nearest free point within ``NUDGE`` first: the robot leaves from where it is,
        and stops as near the goal as it can."""
        fits = self.stands(robot, np.array([a, b]))
        a2 = a if fits[0] else self._nudge(robot, a)
        b2 = b if fits[1] else self._nudge(robot, b)
        if a2 is None or b2 is None:
            return None, "start in collision" if a2 is None else "goal in collision"
        path, reason = self._plan_free_leg(robot, a2, b2, radius)
        if path is None:
            return None, reason
        head = [a] if a2 is not a else []
        return np.vstack([*head, path]), ""

    def _nudge(self, robot: Robot, point: FloatArray) -> FloatArray | None:
        """The nearest point within ``NUDGE`` (same height) where the robot can stand."""
        angles = np.arange(16) * (math.pi / 8)
        for r in np.arange(0.1, NUDGE + 1e-9, 0.1):
            ring = point + r * np.column_stack([np.cos(angles), np.sin(angles),
                                                np.zeros(16)])
            ok = self.stands(robot, ring)
            if ok.any():
                return np.asarray(ring[int(np.argmax(ok))])
        return None

    def _plan_free_leg(self, robot: Robot, a: FloatArray, b: FloatArray,
                       radius: float) -> Planned:
        """A detour by the planner the robot's kind names, within ``WINDOW`` of the leg."""
        self.plans += 1
        seed = (self.seed * 1_000_003 + next(self._counter)) % (2**31)
        kind = _kind(robot)
        leg = Leg(kind, a, b, radius, np.minimum(a, b) - WINDOW, np.maximum(a, b) + WINDOW, seed)
        return PLANNERS.get(kind.planner)(self, leg)

    def floor_grid(self, lo: FloatArray, hi: FloatArray, floor: float) -> GridMap:
        """What stands on the floor (walls, furniture, avatars) between ``lo`` and ``hi``. The
        grid is aligned to one lattice of ``CELL`` for the whole world, so that a point is in
        the same cell, free or not, whichever window it is looked at in."""
        from astralis_des.planning.occupancy import GridMap

        lo = np.floor(np.asarray(lo, dtype=float) / CELL) * CELL

        shape = np.maximum(np.ceil((hi - lo) / CELL).astype(int), 1)
        centers = lo + (np.indices(shape).reshape(2, -1).T + 0.5) * CELL
        occupied = np.zeros(len(centers), dtype=bool)
        z_lo, z_hi = floor + 0.05, floor + 1.8
        solids = self.world.solid_array
        boxes = np.concatenate([solids, self.furniture(np.array([*lo, z_lo]),
                                                        np.array([*hi, z_hi]))])
        tall = (boxes[:, 0, 2] < z_hi) & (boxes[:, 1, 2] > z_lo) & \
            np.all((boxes[:, 0, :2] <= hi + CELL) & (boxes[:, 1, :2] >= lo - CELL), axis=1)
        for box in boxes[tall]:
            occupied |= np.all((centers >= box[0, :2] - CELL / 2) &
                               (centers <= box[1, :2] + CELL / 2), axis=1)
        return GridMap.from_occupancy(occupied.reshape(tuple(shape)), lo, CELL)


def _kind(robot: Robot) -> KindDefaults:
    """The record of the robot's kind: what its body is and how it plans."""
    return KIND_DEFAULTS[robot.kind]


def level_legs(points: FloatArray) -> FloatArray:
    """``points`` with a corner put into each leg that changes height: it climbs where it
    is, then flies level; it flies level, then comes down where it goes (so that a leg to or
    from a point lifted over furniture does not cut the furniture's corner)."""
    out = [points[0]]
    for b in points[1:]:
        a = out[-1]
        if abs(float(b[2] - a[2])) > 1e-6:
            out.append(np.array([a[0], a[1], b[2]]) if b[2] > a[2] else
                       np.array([b[0], b[1], a[2]]))
        out.append(b)
    return np.array(out)
