"""Speed profiles along a path: how far along it a robot is at each time.

A profile is a list of phases, each with a start time, start arc length, start speed and a
constant acceleration: accelerate, cruise, brake, and (for a robot that turns on the spot)
wait at a vertex while turning. Both fidelities time a motion with it: the kinematic one
interpolates it, the physics one flies or drives it as a reference.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from dataclasses import dataclass, field

import numpy as np

from astralis_des.world.geometry import FloatArray

MIN_CORNER = 0.1  # share of the cruise speed kept through a reversal
STOP_ANGLE = math.radians(60)  # a non-holonomic robot turns on the spot beyond this (the rest
# it takes curving: the physics Husky's pure pursuit spins while its aim is more than this off)
MIN_TURN_LEG = 0.25  # m: a shorter leg is a nudge, not worth turning on the spot for


@dataclass(frozen=True)
class Profile:
    t: FloatArray  # phase start times (from 0)
    s: FloatArray  # phase start arc lengths
    v: FloatArray  # phase start speeds
    a: FloatArray  # phase accelerations
    duration: float
    headings: FloatArray  # heading of each leg (for turning robots)
    _phases: tuple[list[float], ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:  # plain floats for one time at a time (:meth:`arc_at`)
        object.__setattr__(self, "_phases", (self.t.tolist(), self.s.tolist(),
                                             self.v.tolist(), self.a.tolist()))

    def arc_at(self, t: float) -> float:
        """:meth:`arc` at one time, in plain floats (the same arithmetic, bit for bit)."""
        times, s, v, a = self._phases
        tt = min(max(t, 0.0), self.duration)
        i = min(max(bisect_right(times, tt) - 1, 0), len(times) - 1)
        dt = tt - times[i]
        return s[i] + v[i] * dt + 0.5 * a[i] * dt * dt

    def arc(self, t: float | FloatArray) -> FloatArray:
        """Arc length reached at time ``t`` (clamped to the profile)."""
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        i = np.clip(np.searchsorted(self.t, tt, side="right") - 1, 0, len(self.t) - 1)
        dt = tt - self.t[i]
        return np.asarray(self.s[i] + self.v[i] * dt + 0.5 * self.a[i] * dt * dt)

    def speeds(self, t: FloatArray) -> FloatArray:
        """Speed at each time in ``t`` (0 after the end)."""
        tt = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        i = np.clip(np.searchsorted(self.t, tt, side="right") - 1, 0, len(self.t) - 1)
        return np.where(np.asarray(t) < self.duration, self.v[i] + self.a[i] * (tt - self.t[i]),
                        0.0)

    def speed(self, t: float) -> float:
        tt = min(max(t, 0.0), self.duration)
        i = max(int(np.searchsorted(self.t, tt, side="right")) - 1, 0)
        return float(self.v[i] + self.a[i] * (tt - self.t[i])) if t < self.duration else 0.0

    def time_of(self, s: FloatArray) -> FloatArray:
        """Time at which each arc length in ``s`` is first reached."""
        s = np.asarray(s, dtype=float)
        moving = np.flatnonzero((self.v > 0) | (self.a > 0))
        if len(moving) == 0:  # a path of no length (or a turn on the spot): there at once
            return np.zeros_like(s)
        starts = self.s[moving]
        j = moving[np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(moving) - 1)]
        ds = np.maximum(s - self.s[j], 0.0)
        v0, a = self.v[j], self.a[j]
        with np.errstate(divide="ignore", invalid="ignore"):
            quad = (-v0 + np.sqrt(np.maximum(v0 * v0 + 2 * a * ds, 0.0))) / a
            lin = ds / v0
        return np.asarray(self.t[j] + np.where(np.abs(a) > 1e-12, quad, lin))


def build(points: FloatArray, speed: float, accel: float | None = None,
          turn_rate: float | None = None, heading: float = 0.0) -> Profile:
    """The profile of a path: cruise at ``speed``; with ``accel``, speed up and slow down
    (to ``speed * cos^2(turn / 2)`` at corners, to rest at the end); with ``turn_rate``, stop
    and turn on the spot at each vertex where the heading changes."""
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1) if len(points) > 1 else np.zeros(0)
    keep = seg > 1e-9
    legs = np.diff(points, axis=0)[keep]
    lengths = seg[keep]
    n = len(lengths)
    headings = np.arctan2(legs[:, 1], legs[:, 0]) if n else np.zeros(0)
    flat = np.hypot(legs[:, 0], legs[:, 1]) > 1e-6 if n else np.zeros(0, dtype=bool)
    # plain floats in the loops below (numpy scalars cost more each; the same arithmetic)
    length = lengths.tolist()
    turns = np.zeros(n)  # turning on the spot before each leg, radians
    if turn_rate is not None:
        previous = heading
        for i, (ahead, level) in enumerate(zip(headings.tolist(), flat.tolist(), strict=True)):
            if level and length[i] >= MIN_TURN_LEG:
                turns[i] = abs(math.remainder(ahead - previous, math.tau))
                previous = ahead
        turns = np.where(turns > STOP_ANGLE, turns - STOP_ANGLE, 0.0)
    # speed allowed at each vertex: 0 at the ends, at turns on the spot, reduced at corners
    v = [float(speed)] * (n + 1)
    if accel is not None:
        v[0] = v[-1] = 0.0
        # each corner's dot product: the same products, summed in the same order as ``@``
        dots = (legs[:-1] * legs[1:]).sum(axis=1).tolist()
        for i in range(1, n):
            cos = dots[i - 1] / (length[i - 1] * length[i])
            v[i] = speed * max((1 + cos) / 2, MIN_CORNER)
        _limit(v, length, accel)
    if turn_rate is not None:
        for i in np.flatnonzero(turns > 0).tolist():
            v[i] = 0.0
        if accel is not None:  # braking before a stop
            _limit(v, length, accel, forward=False)
    turn = turns.tolist()
    phases: list[tuple[float, float, float, float]] = []  # start time, arc, speed, accel
    t = s = 0.0
    for i in range(n):
        if turn[i] > 0 and turn_rate is not None:
            phases.append((t, s, 0.0, 0.0))
            t += turn[i] / turn_rate
        for dur, v0, acc, dist in _trapezoid(length[i], v[i], v[i + 1], speed, accel):
            if dur > 0:
                phases.append((t, s, v0, acc))
                t += dur
                s += dist
    phases.append((t, s, 0.0, 0.0))
    cols = np.array(phases).T
    return Profile(cols[0], cols[1], cols[2], cols[3], t, headings)


def _limit(v: list[float], length: list[float], accel: float, forward: bool = True) -> None:
    """Lower the speeds at the vertices to what ``accel`` reaches over each leg: from the
    start forwards (then back from the end), or back from the end only."""
    if forward:
        for i in range(len(length)):
            v[i + 1] = min(v[i + 1], math.sqrt(v[i] ** 2 + 2 * accel * length[i]))
    for i in range(len(length) - 1, -1, -1):
        v[i] = min(v[i], math.sqrt(v[i + 1] ** 2 + 2 * accel * length[i]))


def _trapezoid(length: float, v0: float, v1: float, vmax: float,
               accel: float | None) -> list[tuple[float, float, float, float]]:
    """Phases (duration, start speed, acceleration, distance) covering one leg."""
    if accel is None or (v0 == vmax and v1 == vmax):
        return [(length / vmax, vmax, 0.0, length)]
    peak = min(vmax, math.sqrt(max((2 * accel * length + v0 * v0 + v1 * v1) / 2, 0.0)))
    d_up = (peak * peak - v0 * v0) / (2 * accel)
    d_down = (peak * peak - v1 * v1) / (2 * accel)
    cruise = max(length - d_up - d_down, 0.0)
    return [((peak - v0) / accel, v0, accel, d_up),
            (cruise / peak if peak > 0 else 0.0, peak, 0.0, cruise),
            ((peak - v1) / accel, peak, -accel, d_down)]
