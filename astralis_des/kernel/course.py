"""What a kinematic motion derives from its path and speed parameters alone: arc lengths, the
speed profile, when each vertex is passed, the legs that set a heading. A process's missions
drive the same routes and patterns again and again, so these are kept (bounded), keyed on the
path's bytes and every parameter, read-only and shared by the motions that follow them.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Callable, Hashable
from functools import cached_property, lru_cache
from typing import Any, TypeVar

import numpy as np

from astralis_des.kernel.profile import Profile, build
from astralis_des.world.geometry import FloatArray

KEPT = 4096  # courses a process keeps (the least recently used dropped)
DERIVED = 8  # values derived from a course (by key) that it keeps
T = TypeVar("T")


class Course:
    """A path's arc lengths and profile, and (on first use) its vertices' times and its
    level legs; poses along it one at a time in plain floats, as ``np.interp`` gives them."""

    def __init__(self, points: FloatArray, profile: Profile) -> None:
        self.points = points
        self.profile = profile
        seg = np.linalg.norm(np.diff(points, axis=0), axis=1) if len(points) > 1 \
            else np.zeros(0)
        self.cum = np.concatenate([[0.0], np.cumsum(seg)])
        self.cum.flags.writeable = False
        self._cum: list[float] = self.cum.tolist()
        self._axes: list[list[float]] = points.T.tolist()
        self._times: FloatArray | None = None
        self._legs: tuple[list[float], list[int], list[float]] | None = None
        self._derived: dict[Hashable, Any] = {}

    def derived(self, key: Hashable, make: Callable[[], T]) -> T:
        """What ``make`` derives from the course alone and ``key`` (sensing samples along
        it), made once: the last ``DERIVED`` keys kept."""
        if key not in self._derived:
            if len(self._derived) >= DERIVED:
                del self._derived[next(iter(self._derived))]
            self._derived[key] = make()
        value: T = self._derived[key]
        return value

    def point(self, s: float) -> list[float]:
        """The point at arc length ``s``: ``np.interp`` on each axis, bit for bit."""
        cum = self._cum
        n = len(cum)
        if n == 1 or s < cum[0]:
            return [axis[0] for axis in self._axes]
        if s >= cum[-1]:
            return [axis[-1] for axis in self._axes]
        j = bisect_right(cum, s) - 1
        if cum[j] == s:
            return [axis[j] for axis in self._axes]
        x0, x1 = cum[j], cum[j + 1]
        out = []
        for axis in self._axes:
            y0, y1 = axis[j], axis[j + 1]
            slope = (y1 - y0) / (x1 - x0)
            value = slope * (s - x0) + y0
            if math.isnan(value):
                value = slope * (s - x1) + y1
                if math.isnan(value) and y0 == y1:
                    value = y0
            out.append(value)
        return out

    def vertex_times(self) -> FloatArray:
        """Seconds after the start at which each vertex is reached (read-only)."""
        if self._times is None:
            times = np.asarray(self.profile.time_of(self.cum))
            times.flags.writeable = False
            self._times = times
        return self._times

    @cached_property
    def in_order(self) -> bool:
        """Whether the vertices' times never decrease (then those passed by a time are the
        first ones)."""
        return bool(np.all(np.diff(self.vertex_times()) >= 0))

    def level_legs(self) -> tuple[list[float], list[int], list[float]]:
        """The legs that move horizontally, in order: where each starts (arc length), its
        index among the legs of some length (the profile's ``headings``), its heading."""
        if self._legs is None:
            legs = np.flatnonzero(np.diff(self.cum) > 1e-9)
            steps = np.diff(self.points, axis=0)[legs]
            flat = np.flatnonzero(np.hypot(steps[:, 0], steps[:, 1]) > 1e-6)
            heads = [float(np.arctan2(dy, dx)) for dx, dy in steps[flat, :2]]
            self._legs = (self.cum[legs[flat]].tolist(), flat.tolist(), heads)
        return self._legs

    def heading_at(self, s: float, before: float, turns: bool) -> float:
        """The heading once ``s`` is reached: that of the last level leg begun (the
        profile's for a robot that ``turns`` on the spot), else ``before``."""
        starts, index, heads = self.level_legs()
        k = bisect_right(starts, s + 1e-9)
        if k == 0:
            return before
        headings = self.profile.headings
        return float(headings[index[k - 1]]) if turns and len(headings) else heads[k - 1]


def course_of(points: FloatArray, speed: float, accel: float | None = None,
              turn_rate: float | None = None, heading: float = 0.0) -> Course:
    """The course of ``points`` under these parameters, built once and kept."""
    pts = np.ascontiguousarray(points, dtype=float)
    return _course(pts.tobytes(), pts.shape, speed, accel, turn_rate, heading)


@lru_cache(maxsize=KEPT)
def _course(raw: bytes, shape: tuple[int, ...], speed: float, accel: float | None,
            turn_rate: float | None, heading: float) -> Course:
    points = np.frombuffer(raw, dtype=float).reshape(shape)  # read-only
    profile = build(points, speed, accel, turn_rate, heading)
    for column in (profile.t, profile.s, profile.v, profile.a, profile.headings):
        column.flags.writeable = False
    return Course(points, profile)
