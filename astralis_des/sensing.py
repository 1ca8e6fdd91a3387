"""The kinematic fidelity's sensing model: a detection radius plus a line of sight.

Physics fidelity replaces it with rendered cameras; both answer the same two questions: when,
along a motion, is the target first seen, and what share of a room's floor did the robot see.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from astralis_des.kernel.robot import Motion, Robot
from astralis_des.kinds import TARGET_HEIGHT
from astralis_des.world.geometry import FloatArray, resample
from astralis_des.world.model import Room, World

SAMPLE_STEP = 0.25  # m between sensing samples along a path
CELL = 0.5  # m, floor cells for coverage


@dataclass(frozen=True)
class Sighting:
    t: float  # seconds after the motion's start
    robot_position: tuple[float, float, float]
    distance: float


class GeometricSensor:
    """Detection and coverage from the world's solids and the target's position."""

    def __init__(self, world: World, target: FloatArray) -> None:
        self.world = world
        self.target = np.asarray(target, dtype=float)

    def first_sighting(self, robot: Robot, motion: Motion) -> Sighting | None:
        pts, s = resample(motion.points, SAMPLE_STEP)
        return self._first(robot, pts, motion.time_of(s))

    def sighting_from(self, robot: Robot, position: FloatArray) -> Sighting | None:
        return self._first(robot, np.asarray(position, dtype=float)[None, :], np.zeros(1))

    def _first(self, robot: Robot, pts: FloatArray, times: FloatArray) -> Sighting | None:
        d = np.linalg.norm(pts - self.target, axis=1)
        near = np.nonzero(d <= robot.detection_radius)[0]
        if len(near) == 0:
            return None
        clear = self.world.line_of_sight(pts[near], np.repeat(self.target[None, :], len(near), 0))
        if not clear.any():
            return None
        i = int(near[np.argmax(clear)])
        x, y, z = (float(v) for v in pts[i])
        return Sighting(float(times[i]), (x, y, z), float(d[i]))

    def coverage(self, robot: Robot, points: FloatArray, room: Room) -> float:
        """Share of ``room``'s floor cells seen from any point of the path ``points``."""
        cells = floor_cells(room)
        pts, _ = resample(np.asarray(points, dtype=float), CELL)
        d = np.linalg.norm(pts[:, None, :] - cells[None, :, :], axis=2)
        pi, ci = np.nonzero(d <= robot.detection_radius)
        if len(pi) == 0:
            return 0.0
        # A room is an empty convex box: from inside it every cell is in sight.
        lo, hi = np.asarray(room.box.lo), np.asarray(room.box.hi)
        inside = np.all((pts >= lo) & (pts <= hi), axis=1)
        seen = np.zeros(len(cells), dtype=bool)
        seen[ci[inside[pi]]] = True
        outside = ~inside[pi] & ~seen[ci]
        if outside.any():
            clear = self.world.line_of_sight(pts[pi[outside]], cells[ci[outside]])
            seen[ci[outside][clear]] = True
        return float(seen.mean())


def floor_cells(room: Room) -> FloatArray:
    """Centres of the room's floor cells, at the height of a sitting or laying person."""
    lo, hi = np.asarray(room.box.lo), np.asarray(room.box.hi)
    xs = np.arange(lo[0] + CELL / 2, hi[0], CELL)
    ys = np.arange(lo[1] + CELL / 2, hi[1], CELL)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, lo[2] + TARGET_HEIGHT)])
