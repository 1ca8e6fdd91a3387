"""The pose sensors of a run: built from the mission, read at their rates from the robots'
past poses (exact from their motions in the kinematic fidelity, sampled from their bodies in
physics), worked out in batches when asked for."""

from __future__ import annotations

import math
from collections.abc import Callable, Generator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import simpy

from astralis_des.kernel.robot import Motion, Robot
from astralis_des.navsensors.models import (
    Barometer,
    Gnss,
    Magnetometer,
    Origin,
    Readings,
    yaw_rotation,
)
from astralis_des.streams import stream
from astralis_des.world.geometry import FloatArray

if TYPE_CHECKING:
    from astralis_des.kernel.contracts import Host


Poses = Callable[[Robot, FloatArray], tuple[FloatArray, FloatArray]]
MODELS: dict[str, Callable[..., Any]] = {}  # sensor name -> model(host, member, index)


def site_origin(host: Host) -> Origin:
    """The mission's ``site`` when it gives one, else the world's georeference (an imported
    scan's), else the default site."""
    spec, world = host.mission.spec, host.world
    if "site" not in spec.model_fields_set and world.origin is not None:
        return Origin(*world.origin)
    return Origin(spec.site.latitude, spec.site.longitude, spec.site.altitude)


def _gnss(host: Host, member: Any, index: int) -> Gnss:
    g, spec = member.sensor_set.gnss, host.mission.spec
    return Gnss(host.world, site_origin(host), stream(spec.seed, "gnss", index),
                g.horizontal_noise, g.vertical_noise, g.satellites, g.degraded_below)


def _barometer(host: Host, member: Any, index: int) -> Barometer:
    b, spec = member.sensor_set.barometer, host.mission.spec
    return Barometer(site_origin(host), stream(spec.seed, "barometer", index), b.noise,
                     b.drift, b.drift_time)


def _magnetometer(host: Host, member: Any, index: int) -> Magnetometer:
    m, spec = member.sensor_set.magnetometer, host.mission.spec
    return Magnetometer(stream(spec.seed, "magnetometer", index), spec.site.magnetic_field,
                        m.noise, m.bias)


MODELS.update(gnss=_gnss, barometer=_barometer, magnetometer=_magnetometer)


@dataclass
class PoseSensors:
    """The GNSS, barometers and magnetometers of a run's team. Each reads at its rate from
    the mission's start (at ``k / rate`` s), from the robot's pose then: ``poses`` gives the
    positions and attitudes (world from body) of a robot at past times, exactly from its
    motions in the kinematic fidelity, from samples of its body in physics. Readings are
    worked out when asked for (the API, the outputs), many at once."""

    robots: dict[str, Robot]
    poses: Poses
    sensors: dict[tuple[str, str], tuple[Any, float]] = field(default_factory=dict)
    _parts: dict[tuple[str, str], list[Readings]] = field(default_factory=dict)
    _next: dict[tuple[str, str], int] = field(default_factory=dict)

    @classmethod
    def of(cls, host: Host, poses: Poses) -> PoseSensors:
        out = cls(host.robots, poses)
        for index, member in enumerate(host.mission.spec.team):
            for name, model in MODELS.items():
                spec = getattr(member.sensor_set, name)
                if spec is not None:
                    out.sensors[member.id, name] = (model(host, member, index), spec.rate)
        return out

    def rates(self, rid: str) -> list[float]:
        return sorted({rate for (r, _), (_, rate) in self.sensors.items() if r == rid})

    def update(self, now: float) -> None:
        """Work out every reading due by ``now`` (a robot's poses once for all its sensors)."""
        due: dict[str, list[tuple[tuple[str, str], FloatArray]]] = {}
        for key, (_, rate) in self.sensors.items():
            first, last = self._next.get(key, 0), math.floor(now * rate + 1e-9)
            if last >= first:
                due.setdefault(key[0], []).append((key, np.arange(first, last + 1) / rate))
                self._next[key] = last + 1
        for rid, wanted in due.items():
            every = np.unique(np.concatenate([t for _, t in wanted]))
            positions, rotations = self.poses(self.robots[rid], every)
            for key, t in wanted:
                rows = np.searchsorted(every, t)
                part = self.sensors[key][0].read(t, positions[rows], rotations[rows])
                self._parts.setdefault(key, []).append(part)

    def readings(self, rid: str, name: str) -> Readings:
        parts = self._parts.get((rid, name), [])
        if len(parts) > 1:
            self._parts[rid, name] = parts = [Readings.joined(parts)]
        return parts[0] if parts else Readings(np.zeros(0), {})


def motion_poses(robot: Robot, times: FloatArray) -> tuple[FloatArray, FloatArray]:
    """A kinematic robot's positions and level attitudes at past ``times`` (sorted), from the
    motions it ran (``Robot.history``) and the one it runs: along a motion it faces the way
    its current leg goes, between motions it stands where the last one ended, facing as it
    ended. All motions at once: their speed profiles' phases and their paths are laid end
    to end (a path's arc length offset past the one before), so each time is a lookup."""
    t = np.asarray(times, dtype=float)
    entries = list(robot.history)
    if isinstance(robot.motion, Motion):
        entries.append((robot.motion.t0, math.inf, robot.motion, robot.heading))
    if not entries:
        return np.repeat(robot.pose[None, :], len(t), axis=0), yaw_rotation(
            np.full(len(t), robot.heading))
    starts = np.array([e[0] for e in entries])
    ends = np.array([e[1] for e in entries])
    i = np.maximum(np.searchsorted(starts, t, side="right") - 1, 0)
    before = t < starts[0]
    m0 = entries[0][2]
    durations = np.array([e[2].profile.duration for e in entries])
    tt = np.clip(np.minimum(t, ends[i]) - starts[i], 0.0, durations[i])
    # the phases of every profile, keyed by entry + time / (duration + 1): one sorted array
    keys, s0, v0, a0, t_ph, offsets, cum, points = [], [], [], [], [], [], [], []
    offset = 0.0
    for k, (_, _, m, _) in enumerate(entries):
        prof = m.profile
        keys.append(k + prof.t / (prof.duration + 1.0))
        s0.append(prof.s)
        v0.append(prof.v)
        a0.append(prof.a)
        t_ph.append(prof.t)
        offsets.append(offset)
        cum.append(offset + m.cum)
        points.append(m.points)
        offset += float(m.cum[-1]) + 1.0
    yaws = _leg_yaws(points, [e[2].heading for e in entries])
    phase = np.searchsorted(np.concatenate(keys), i + tt / (durations[i] + 1.0),
                            side="right") - 1
    dt = tt - np.concatenate(t_ph)[phase]
    arc = np.concatenate(s0)[phase] + np.concatenate(v0)[phase] * dt \
        + 0.5 * np.concatenate(a0)[phase] * dt * dt
    lengths = np.array([float(e[2].cum[-1]) for e in entries])
    along = np.array(offsets)[i] + np.clip(arc, 0.0, lengths[i])
    xp, fp = np.concatenate(cum), np.concatenate(points)
    positions = np.column_stack([np.interp(along, xp, fp[:, k]) for k in range(3)])
    leg = np.clip(np.searchsorted(xp, along, side="right") - 1, 0, len(xp) - 1)
    yaw = np.where(t > ends[i], np.array([e[3] for e in entries])[i], yaws[leg])
    positions[before], yaw[before] = m0.points[0], m0.heading
    return positions, yaw_rotation(yaw)


def _leg_yaws(points: list[FloatArray], headings: list[float]) -> FloatArray:
    """For each vertex of the paths laid end to end, the heading of the leg leaving it (the
    last leg's at a path's end); a leg that does not move horizontally keeps the heading
    before it, and a path starts from its motion's heading."""
    every = np.concatenate(points)
    starts = np.cumsum([0] + [len(p) for p in points[:-1]])
    legs = np.diff(every[:, :2], axis=0, append=every[-1:, :2])
    ok = np.hypot(legs[:, 0], legs[:, 1]) > 1e-6
    value = np.arctan2(legs[:, 1], legs[:, 0])
    ends = starts[1:] - 1  # the leg from a path's last vertex to the next path's first
    ok[ends] = False
    ok[-1] = False
    first = starts[~ok[starts]]  # a path whose first leg does not move: its heading
    value[first] = np.asarray(headings)[~ok[starts]]
    ok[first] = True
    filled: FloatArray = value[np.maximum.accumulate(np.where(ok, np.arange(len(ok)), 0))]
    return filled


@dataclass
class BodySamples:
    """A simulated body's pose sampled at each reading time of its robot's pose sensors
    (physics): ``body_pose(robot)`` gives its position and attitude now."""

    env: simpy.Environment
    body_pose: Callable[[Robot], tuple[FloatArray, FloatArray]]
    samples: dict[str, dict[float, tuple[FloatArray, FloatArray]]] = field(default_factory=dict)

    def start(self, sensors: PoseSensors) -> None:
        for rid, robot in sensors.robots.items():
            rates = sensors.rates(rid)
            if rates:
                self.samples[rid] = {}
                self.env.process(self._sample(robot, rates))

    def _sample(self, robot: Robot, rates: list[float]) -> Generator[simpy.Event, Any, None]:
        """At ``k / rate`` for each rate and k (a time two rates share, once)."""
        kept, ks = self.samples[robot.id], [0] * len(rates)
        while True:
            t = min(k / r for k, r in zip(ks, rates, strict=True))
            if t > self.env.now:
                yield self.env.timeout(t - float(self.env.now))
            kept[t] = self.body_pose(robot)
            ks = [k + 1 if k / r == t else k for k, r in zip(ks, rates, strict=True)]

    def poses(self, robot: Robot, times: FloatArray) -> tuple[FloatArray, FloatArray]:
        kept = self.samples[robot.id]
        # a time due now whose sampling event has not run yet is read now
        got = [kept[t] if t in kept else self.body_pose(robot) for t in times.tolist()]
        return np.array([g[0] for g in got]), np.array([g[1] for g in got])
