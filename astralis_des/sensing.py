"""The kinematic fidelity's sensing model: a detection radius plus a line of sight.

Walls, slabs, obstacles, furniture and avatars block sight. Physics fidelity replaces the
model with rendered cameras; both answer the same two questions: when, along a motion, is the
target first seen, and what share of a room's floor did the robot see.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.kernel.robot import Motion, Robot
from astralis_des.kinds import TARGET_HEIGHT
from astralis_des.world.geometry import FloatArray, resample
from astralis_des.world.model import Room

if TYPE_CHECKING:
    from astralis_des.kernel.scene import Scene, Target

SAMPLE_STEP = 0.25  # m between sensing samples along a path
CELL = 0.5  # m, floor cells for coverage


@dataclass(frozen=True)
class Sighting:
    t: float  # seconds after the motion's start
    robot_position: tuple[float, float, float]
    target_position: tuple[float, float, float]
    distance: float


class GeometricSensor:
    """Detection and coverage from the scene's bodies and the target's whereabouts."""

    def __init__(self, scene: Scene, target: Target) -> None:
        self.scene = scene
        self.target = target

    def first_sighting(self, robot: Robot, motion: Motion) -> Sighting | None:
        pts, s = resample(motion.points, SAMPLE_STEP)
        times = motion.time_of(s)
        return self._first(robot, pts, times, self.target.positions_at(motion.t0 + times))

    def sighting_from(self, robot: Robot, position: FloatArray, now: float) -> Sighting | None:
        here = np.asarray(position, dtype=float)[None, :]
        return self._first(robot, here, np.zeros(1), self.target.positions_at(np.array([now])))

    def _first(self, robot: Robot, pts: FloatArray, times: FloatArray,
               targets: FloatArray) -> Sighting | None:
        d = np.linalg.norm(pts - targets, axis=1)
        near = np.nonzero(d <= robot.detection_radius)[0]
        if len(near) == 0:
            return None
        clear = self.scene.line_of_sight(pts[near], targets[near])
        if not clear.any():
            return None
        i = int(near[np.argmax(clear)])
        return Sighting(float(times[i]), _xyz(pts[i]), _xyz(targets[i]), float(d[i]))

    def coverage(self, robot: Robot, points: FloatArray, room: Room) -> float:
        """Share of ``room``'s free floor cells (not under furniture) seen from any point of
        the path ``points``."""
        cells = floor_cells(room)
        boxes = self.scene.still_boxes([room.id])
        if len(boxes):
            under = np.any(np.all((cells[:, None, :2] >= boxes[None, :, 0, :2]) &
                                  (cells[:, None, :2] <= boxes[None, :, 1, :2]), axis=2), axis=1)
            cells = cells[~under]
            if len(cells) == 0:
                return 0.0
        pts, _ = resample(np.asarray(points, dtype=float), CELL)
        d = np.linalg.norm(pts[:, None, :] - cells[None, :, :], axis=2)
        pi, ci = np.nonzero(d <= robot.detection_radius)
        if len(pi) == 0:
            return 0.0
        seen = np.zeros(len(cells), dtype=bool)
        lo, hi = np.asarray(room.box.lo), np.asarray(room.box.hi)
        inside = np.all((pts >= lo) & (pts <= hi), axis=1)
        if not len(boxes):
            # An empty room is a convex box: from inside it every cell is in sight.
            seen[ci[inside[pi]]] = True
        todo = ~seen[ci]
        if todo.any():
            clear = self.scene.line_of_sight(pts[pi[todo]], cells[ci[todo]])
            seen[ci[todo][clear]] = True
        return float(seen.mean())


def floor_cells(room: Room) -> FloatArray:
    """Centres of the room's floor cells, at the height of a sitting or laying person."""
    lo, hi = np.asarray(room.box.lo), np.asarray(room.box.hi)
    xs = np.arange(lo[0] + CELL / 2, hi[0], CELL)
    ys = np.arange(lo[1] + CELL / 2, hi[1], CELL)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, lo[2] + TARGET_HEIGHT)])


def _xyz(p: FloatArray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))
