"""The kinematic fidelity's sensing model: the shared detection model on the camera's view.

A robot's camera (:class:`View`) detects the target when it would show at least
``min_pixels`` of it (:mod:`astralis_des.detection`: the target's box projected under the
camera's intrinsics, less what walls, slabs, obstacles, furniture and avatars hide), within
its range when one is set. A gimballed camera (UAV, person) turns to the direction of
travel; a body camera (UGV) turns with the body. Physics fidelity counts the same pixels in
rendered frames; both answer the same questions: when, along a motion, is the target first
seen, where was it estimated to be, and what share of a room's floor did the robot see (the
floor cells where a target would show ``min_pixels`` with its centre in sight).
"""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.compiled import kernels
from astralis_des.detection import PROBES, Sighting, cull, predict_pixels, shows_unhidden
from astralis_des.kernel.robot import Motion, Robot
from astralis_des.kinds import TARGET_HEIGHT
from astralis_des.view import Axes, View, look_headings, pick, travel_headings
from astralis_des.world.geometry import FloatArray, resample
from astralis_des.world.model import Room, World

if TYPE_CHECKING:
    from astralis_des.world.scene import Scene, Target

SAMPLE_STEP = 0.25  # m between sensing samples along a path
CELL = 0.5  # m, floor cells for coverage
CHUNK = 16  # looks judged at a time, in time order, until one detects
BOUND_SHARE = 0.8  # of min_pixels the unhidden bound (sampled coarser) must reach
PASSES = 6  # interleaved passes over a path's points when judging coverage
FEW_PAIRS = 128  # pairs of point and cell judged without culling first
MEMO_SWEEPS = 65536  # coverage answers a world keeps (16-byte digests of their inputs)
__all__ = ["GeometricSensor", "Sighting", "in_frame"]


class GeometricSensor:
    """Detection and coverage from the scene's bodies and the target's whereabouts."""

    def __init__(self, scene: Scene, target: Target,
                 rng: np.random.Generator | None = None) -> None:
        self.scene = scene
        self.target = target
        self.rng = rng if rng is not None else np.random.default_rng(0)

    def first_sighting(self, robot: Robot, motion: Motion) -> Sighting | None:
        if robot.view is None:
            return None
        pts, headings, times = motion.derived(("sightings", SAMPLE_STEP, robot.heading),
                                              lambda: _samples(motion, robot.heading))
        return self._first(robot, pts, headings, times,
                           self.target.positions_at(motion.t0 + times))

    def sighting_from(self, robot: Robot, position: FloatArray, now: float) -> Sighting | None:
        """Looking from ``position`` now (around, for a camera that pans while waiting)."""
        if robot.view is None:
            return None
        headings = look_headings(robot.view, robot.heading)
        here = np.repeat(np.asarray(position, dtype=float)[None, :], len(headings), axis=0)
        targets = np.repeat(self.target.positions_at(np.array([now])), len(headings), axis=0)
        return self._first(robot, here, headings, np.zeros(len(headings)), targets)

    def _first(self, robot: Robot, pts: FloatArray, headings: FloatArray, times: FloatArray,
               targets: FloatArray) -> Sighting | None:
        view = robot.view
        assert view is not None
        size = np.asarray(self.target.size, dtype=float)
        # cheap tests first: can any corner of the box be in the frame, and would the box
        # show enough pixels if nothing hid it?
        every = np.arange(len(pts))
        axes = view.axes(headings)  # once per look, the rows of each test picked from them
        near, _ = in_frame(view, pts, headings, targets, size, every, every, axes)
        if len(near) == 0:
            return None
        bound = predict_pixels(view, pts[near], headings[near], targets[near], size, None,
                               pick(axes, near))
        near = near[bound >= BOUND_SHARE * view.min_pixels]  # coarser: a margin
        for start in range(0, len(near), CHUNK):
            idx = near[start:start + CHUNK]
            pixels = predict_pixels(view, pts[idx], headings[idx], targets[idx], size,
                                    self._sight, pick(axes, idx))
            hits = np.flatnonzero(pixels >= view.min_pixels)
            if len(hits):
                i, count = int(idx[hits[0]]), int(pixels[hits[0]])
                return self._sighting(view.position_noise, pts[i], targets[i], float(times[i]),
                                      count)
        return None

    def _sight(self, p0: FloatArray, p1: FloatArray,
               rooms: list[str] | None = None) -> np.ndarray:
        """Where nothing lies between ``p0[m]`` and ``p1[m]``. Looking into a room is what
        furnishes it (in kinematic fidelity, the team's first look at it): the rooms the
        lines start or end in (``rooms``, when the caller knows them) are furnished first,
        then the scene is asked."""
        scene = self.scene
        if rooms is None:
            rooms = scene.rooms_at(np.concatenate([np.atleast_2d(p0), np.atleast_2d(p1)]))
        scene.furnish(rooms)
        return scene.line_of_sight(p0, p1, rooms)

    def _sighting(self, noise_share: float, eye: FloatArray, target: FloatArray, t: float,
                  pixels: int) -> Sighting:
        distance = float(np.linalg.norm(eye - target))
        noise = self.rng.normal(0.0, noise_share * distance, 3)
        estimate = target + noise
        return Sighting(t, _xyz(eye), _xyz(target), distance, _xyz(estimate),
                        float(np.linalg.norm(noise)), pixels)

    def coverage(self, robot: Robot, points: FloatArray, room: Room,
                 headings: FloatArray | None = None) -> float:
        """Share of ``room``'s free floor cells (not under furniture) seen from the path
        ``points`` (facing its direction of travel, or ``headings`` given per point). The
        robot looks into the room: it is furnished first if it was not yet."""
        if robot.view is None:
            return 0.0
        full, alone = self._floor(room)
        self.scene.furnish([room.id])  # looking into a room is what furnishes it
        boxes = self.scene.still_boxes([room.id])
        keep = np.ones(len(full), dtype=bool)
        if len(boxes):
            compiled = kernels()
            if compiled is not None:  # the same cells, pair by pair
                under = compiled.within(full, boxes[:, 0], boxes[:, 1], 2)
            else:
                x, y = full[:, 0:1], full[:, 1:2]  # axis by axis: the same cells, fewer calls
                under = ((x >= boxes[None, :, 0, 0]) & (x <= boxes[None, :, 1, 0])
                         & (y >= boxes[None, :, 0, 1]) & (y <= boxes[None, :, 1, 1]))
            keep = ~np.asarray(under.any(axis=1))
            if not keep.any():
                return 0.0
        view = robot.view
        pts, heads = _sample_path(robot, np.asarray(points, dtype=float), headings)
        size = np.asarray(self.target.size, dtype=float)
        if not _within(self.scene.world, room, pts):  # another room's furniture may matter
            return self._coverage(view, pts, heads, full, keep, boxes, size, room, None)
        # the answer depends on these alone: kept on the world (a tune's next trial, a study's
        # next variant flies the same sweep of the same furnished room)
        digest = _digest(pts, heads, boxes, size)
        memo = self.scene.world.memo("coverage", MEMO_SWEEPS)
        key = (view, room.id, len(pts), len(boxes), digest)
        if key not in memo:
            # the sight lines start and end in this room alone (its floor cells lie in no
            # other room): no need to find the rooms of their ends again
            memo[key] = self._coverage(view, pts, heads, full, keep, boxes, size, room,
                                       [room.id] if alone else None)
        return float(memo[key])

    def _floor(self, room: Room) -> tuple[FloatArray, bool]:
        """The room's :func:`floor_cells` (read-only), and whether they all lie in it and in
        no other room: once per world and room."""
        memo = self.scene.world.memo("floor_cells", 4096)
        if room.id not in memo:
            full = floor_cells(room)
            full.setflags(write=False)
            lo, hi = np.asarray(room.box.lo), np.asarray(room.box.hi)
            alone = bool(np.all((full >= lo) & (full <= hi))) and \
                self.scene.rooms_at(full) == [room.id]
            memo[room.id] = (full, alone)
        found: tuple[FloatArray, bool] = memo[room.id]
        return found

    def _coverage(self, view: View, pts: FloatArray, heads: FloatArray, full: FloatArray,
                  keep: np.ndarray, boxes: FloatArray, size: FloatArray, room: Room,
                  rooms: list[str] | None) -> float:
        """A cell (of ``full[keep]``) is seen when some point of the path shows a target
        there with enough pixels and in sight. The path's points are taken in ``PASSES``
        interleaved passes (every ``PASSES``-th point, then the next...), each judging only
        the cells no pass has seen: the first pass spans the whole path and sees most of the
        room, so the later ones have little left to judge. The seen set is the same as
        judging every pair at once. Which pairs of the first pass would show enough pixels
        does not depend on the furniture: it is kept per room and path (the next seed
        furnishes the room anew, the UAV flies the same sweep)."""
        axes = view.axes(heads)  # once per point of the path, not per pair
        cells = full[keep]
        seen = np.zeros(len(cells), dtype=bool)
        lo, hi = np.asarray(room.box.lo), np.asarray(room.box.hi)
        in_room = np.all((pts >= lo) & (pts <= hi), axis=1)
        rows = np.arange(0, len(pts), PASSES)
        shown = self._first_pass(view, pts, heads, axes, full, size, room)[:, keep]
        r, c = np.nonzero(shown)
        self._judge(pts, cells, rows[r], c, seen, in_room, len(boxes) == 0, rooms)
        todo = np.flatnonzero(~seen)
        if len(pts) > 1 and len(todo):
            # the later passes' points at once, for the cells left after the first pass, in
            # pass order (so a cell's first sight line is from the earliest pass that shows
            # it): two calls of the sight test instead of two a pass
            later = np.zeros((len(pts), len(cells)), dtype=bool)
            after = np.flatnonzero(np.arange(len(pts)) % PASSES)
            later[_shown(view, pts, axes, cells, size, after, todo)] = True
            order = np.concatenate([np.arange(first, len(pts), PASSES)
                                    for first in range(1, min(PASSES, len(pts)))])
            r, c = np.nonzero(later[order][:, todo])
            self._judge(pts, cells, order[r], todo[c], seen, in_room, len(boxes) == 0, rooms)
        return float(seen.mean())

    def _judge(self, pts: FloatArray, cells: FloatArray, pi: np.ndarray, ci: np.ndarray,
               seen: np.ndarray, in_room: np.ndarray, empty: bool,
               rooms: list[str] | None) -> None:
        """Mark ``seen`` the cells of the pairs (point ``pi``, cell ``ci``) in sight: from a
        point inside an ``empty`` room every cell is (a convex box), else by sight lines."""
        if empty:
            seen[ci[in_room[pi]]] = True
        left = ~seen[ci]
        if left.any():
            self._see(pts, cells, pi[left], ci[left], seen, rooms)

    def _see(self, pts: FloatArray, cells: FloatArray, pi: np.ndarray, ci: np.ndarray,
             seen: np.ndarray, rooms: list[str] | None) -> None:
        """Mark ``seen`` the cells of the pairs (point ``pi``, cell ``ci``) with a clear line
        of sight: one pair a cell first (most are clear), then the other pairs of the cells
        left (the same cells as every pair judged at once)."""
        _, once = np.unique(ci, return_index=True)
        clear = self._sight(pts[pi[once]], cells[ci[once]], rooms)
        seen[ci[once][clear]] = True
        rest = np.ones(len(ci), dtype=bool)
        rest[once] = False
        rest &= ~seen[ci]
        if rest.any():
            clear = self._sight(pts[pi[rest]], cells[ci[rest]], rooms)
            seen[ci[rest][clear]] = True

    def _first_pass(self, view: View, pts: FloatArray, heads: FloatArray, axes: Axes,
                    full: FloatArray, size: FloatArray, room: Room) -> np.ndarray:
        """``(rows, cells)``: whether the first pass's points (every ``PASSES``-th) would show
        a target on each of the room's floor cells with enough pixels, if nothing hid it."""
        memo = self.scene.world.memo("first_pass", MEMO_SWEEPS)
        key = (view, room.id, len(pts), _digest(pts, heads, size))
        rows = np.arange(0, len(pts), PASSES)
        if key not in memo:
            pi, ci = _shown(view, pts, axes, full, size, rows, np.arange(len(full)))
            shown = np.zeros((len(rows), len(full)), dtype=bool)
            shown[pi // PASSES, ci] = True
            memo[key] = np.packbits(shown, axis=1)
        out: np.ndarray = np.unpackbits(memo[key], axis=1, count=len(full)).astype(bool)
        return out


def _shown(view: View, pts: FloatArray, axes: Axes, cells: FloatArray, size: FloatArray,
           rows: np.ndarray, todo: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (``rows`` x ``todo``) where a target on the cell would show enough pixels
    from the point, if nothing hid it: culled against the frustum, the rest counted (a few
    pairs are all counted: culling them would cost more than it saves)."""
    if len(rows) * len(todo) <= FEW_PAIRS:
        pi, ci = np.repeat(rows, len(todo)), np.tile(todo, len(rows))
        big = shows_unhidden(view, pts, axes, cells, size, pi, ci)
        return pi[big], ci[big]
    sure, maybe = cull(view, pts[rows], pick(axes, rows), cells[todo], size)
    pi, ci = rows[maybe[0]], todo[maybe[1]]
    big = shows_unhidden(view, pts, axes, cells, size, pi, ci)
    return (np.concatenate([rows[sure[0]], pi[big]]),
            np.concatenate([todo[sure[1]], ci[big]]))


def _digest(*arrays: FloatArray) -> bytes:
    """16 bytes standing for the arrays' values (a memo's key)."""
    return hashlib.blake2b(b"".join(np.ascontiguousarray(a, dtype=float).tobytes()
                                    for a in arrays), digest_size=16).digest()


def _within(world: World, room: Room, pts: FloatArray) -> bool:
    """Whether no point of ``pts`` lies in a room other than ``room`` (then the sight lines of
    its coverage meet no furniture but that of ``room``: Scene.line_of_sight)."""
    ids = world.room_ids
    return all(ids[k] == room.id for k in world.rooms_holding(pts).tolist())


def in_frame(view: View, eyes: FloatArray, headings: FloatArray, centres: FloatArray,
             size: FloatArray, ei: np.ndarray, ci: np.ndarray,
             axes: Axes | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (eye ``ei[m]``, target box at ``centres[ci[m]]``) where any corner or the
    centre of the box is in the camera's frame and reach; ``axes``: those of ``headings``."""
    probes = centres[ci][:, None, :] + PROBES[None, :, :] * size
    k = probes.shape[1]
    rows = np.repeat(ei, k)
    inside = view.sees(eyes[rows], headings[rows], probes.reshape(-1, 3),
                       None if axes is None else pick(axes, rows)).reshape(len(ei), k).any(axis=1)
    return ei[inside], ci[inside]


def _sample_path(robot: Robot, points: FloatArray,
                 headings: FloatArray | None) -> tuple[FloatArray, FloatArray]:
    """Points every ``CELL`` along a path and the camera's heading at each; a single point
    looks around (or ahead) as a waiting camera does."""
    assert robot.view is not None
    if headings is not None:
        return points, np.asarray(headings, dtype=float)
    if len(points) == 1:
        heads = look_headings(robot.view, robot.heading)
        return np.repeat(points, len(heads), axis=0), heads
    pts, _ = resample(points, CELL)
    return pts, travel_headings(pts, robot.heading)


def floor_cells(room: Room) -> FloatArray:
    """Centres of the room's floor cells, at the height of a sitting or laying person."""
    lo, hi = np.asarray(room.box.lo), np.asarray(room.box.hi)
    xs = np.arange(lo[0] + CELL / 2, hi[0], CELL)
    ys = np.arange(lo[1] + CELL / 2, hi[1], CELL)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, lo[2] + TARGET_HEIGHT)])


def _samples(motion: Motion, heading: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Points every ``SAMPLE_STEP`` along a motion, the camera's heading at each (from
    ``heading``) and when it is there (after the start): read-only, kept with the motion."""
    pts, s = resample(motion.points, SAMPLE_STEP)
    out = (pts, travel_headings(pts, heading), np.asarray(motion.time_of(s)))
    for part in out:
        part.flags.writeable = False
    return out


def _xyz(p: FloatArray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))
