"""UAVs under door lintels: a UAV flies over the heads of standing people, higher than a
door's lintel leaves room for its body, so its routes come down to pass a doorway and climb
back after it (in both fidelities, the same way)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from astralis_des.world.geometry import FloatArray, segments_hit_boxes

if TYPE_CHECKING:
    from astralis_des.world.model import World


class Robot(Protocol):
    """What the lintel rules need of a robot."""

    kind: str
    height: float

DUCK_STEP = 0.05  # m: the heights a UAV tries, one below the other, to pass under a lintel
DUCK_LOWEST = 1.0  # m over the floor: it flies no lower to pass under one


class Lintels:
    """The navigator's lintel rules (a mixin: it needs ``world`` and ``furniture``)."""

    world: World
    furniture: Callable[[FloatArray, FloatArray], FloatArray]  # still boxes near [lo, hi]

    def _ducked(self, robot: Robot, points: FloatArray, radius: float) -> FloatArray:
        """A UAV's route on the graph, flown under the lintels as the physics route is (the
        other legs as they are: on the graph nothing else is planned)."""
        memo = self.world.memo("ducked", 4096)  # the same legs come again and again
        key = (np.asarray(points, dtype=float).tobytes(), radius, robot.height)
        if key in memo:
            return np.array(memo[key])
        points = self._under_lintels(robot, points, radius)
        free = self._free(points, radius)
        blocked = set(np.flatnonzero(~free(points[:-1], points[1:])).tolist())
        out = [points[0]]
        for i, b in enumerate(points[1:]):
            ducked = self._duck(robot, out[-1], b, free) if i in blocked else None
            out.extend(ducked[1:] if ducked is not None else [b])
        memo[key] = np.array(out)
        return np.array(out)

    def _free(self, points: FloatArray, radius: float,  # type: ignore[no-untyped-def]
              keep_out: float | None = None):
        """A test of many legs at once (``free(a, b)``: a boolean a leg) against the walls
        and slabs near ``points`` grown by ``radius``, and with ``keep_out`` the still
        furniture and people too, grown by ``radius + keep_out`` (as the navigator's
        ``_leg_free``)."""
        reach = radius + (keep_out or 0.0) + 1.0
        lo, hi = points.min(axis=0) - reach, points.max(axis=0) + reach
        solids = self.world.solid_array
        near = solids[np.all((solids[:, 0] <= hi) & (solids[:, 1] >= lo), axis=1)]
        grown = [np.stack([near[:, 0] - radius, near[:, 1] + radius], axis=1)]
        if keep_out is not None:
            things = self.furniture(lo, hi)
            grown.append(np.stack([things[:, 0] - radius - keep_out,
                                   things[:, 1] + radius + keep_out], axis=1))
        boxes = np.concatenate(grown)

        def free(a: FloatArray, b: FloatArray) -> np.ndarray:
            return ~np.asarray(segments_hit_boxes(np.atleast_2d(a), np.atleast_2d(b), boxes))

        return free

    def _heights(self, robot: Robot, point: FloatArray, top: float) -> FloatArray:
        """The heights a UAV tries under a lintel, highest first: below ``top`` down to
        ``DUCK_LOWEST`` over the floor under ``point``."""
        floor = self.world.floor_below(point - np.array([0.0, 0.0, robot.height]))
        return np.arange(top - DUCK_STEP, floor + DUCK_LOWEST - 1e-9, -DUCK_STEP)

    def _under_lintels(self, robot: Robot, points: FloatArray, radius: float) -> FloatArray:
        """A UAV's route points in a doorway too high for the lintel, brought down to the
        highest height that is clear (not below ``DUCK_LOWEST`` over the floor)."""
        out = np.array(points, dtype=float)
        nudge = np.array([1e-6, 0.0, 0.0])
        free = self._free(out, radius)
        for p in out[~free(out, out + nudge)]:
            heights = self._heights(robot, p, float(p[2]))
            lows = np.column_stack([np.full(len(heights), p[0]), np.full(len(heights), p[1]),
                                    heights])
            ok = np.flatnonzero(free(lows, lows + nudge)) if len(lows) else np.zeros(0, int)
            if len(ok):
                out[np.all(out == p, axis=1), 2] = heights[ok[0]]
        return out

    def _duck(self, robot: Robot, a: FloatArray, b: FloatArray,
              free: Any) -> FloatArray | None:
        """A UAV's leg on one storey blocked overhead (a door's lintel): the same leg lower,
        coming down before it and climbing back after, at the highest height where all three
        legs are ``free`` (:meth:`_free`; not below ``DUCK_LOWEST`` over the floor); ``None``
        if none is."""
        below = np.array([0.0, 0.0, robot.height])
        if abs(self.world.floor_below(b - below) - self.world.floor_below(a - below)) > 0.5:
            return None  # a leg between storeys (a stairwell): not a lintel's
        heights = self._heights(robot, a, min(float(a[2]), float(b[2])))
        if not len(heights):
            return None
        a2, b2 = np.repeat(a[None], len(heights), 0), np.repeat(b[None], len(heights), 0)
        a2[:, 2] = b2[:, 2] = heights
        ok = free(a2, b2) & free(np.repeat(a[None], len(heights), 0), a2) & \
            free(b2, np.repeat(b[None], len(heights), 0))
        first = np.flatnonzero(ok)
        return np.array([a, a2[first[0]], b2[first[0]], b]) if len(first) else None
