"""The sensors at work in the physics fidelity, each a SimPy process or an on-demand call.

- **Cameras** look ``rate`` times a second while an action searches, and once (around, for a
  camera that pans) when a robot waits in place. A look first tests whether the target's box
  lies in the camera's frustum at all, and whether it could show enough pixels if nothing hid
  it, then if only walls and slabs did (the shared detection model,
  :mod:`astralis_des.detection`; well under a millisecond); only then is a frame rendered
  (about 30 ms at 320 x 240), and the target is detected when at least ``min_pixels`` of its
  segmentation show (within range, when the camera has one). The estimate is the centroid
  of those pixels' depth points.
  Frames are kept for the recording at ``record_rate``, rendered at half resolution, when
  the run's outputs record them (``Host.recorded``): a run without a recording renders none.
- **Lidars** scan at their rate while their robot moves; a UGV slows down for the nearest
  return ahead of it (the local planner's safety bubble).
- **IMUs** read at their rate while their robot moves.

Every sensor's wall time and calls are counted (:class:`SensorClock`) for the benchmark.
"""

from __future__ import annotations

import math
import time
from collections.abc import Generator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import simpy

from astralis_des.detection import predict_pixels
from astralis_des.kernel.perceived import ImuTrace, KeptCloud, KeptFrame, KeptScan
from astralis_des.kernel.robot import Robot
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.mission.spec import CameraSpec, ImuSpec, Lidar3dSpec, LidarSpec
from astralis_des.physics.lidar3d import Lidar3D
from astralis_des.physics.offscreen import Offscreen
from astralis_des.physics.sensors import Camera, Frame, Imu, Intrinsics, Lidar2D
from astralis_des.sensing import Sighting, in_frame
from astralis_des.streams import stream
from astralis_des.view import View, look_headings
from astralis_des.world.geometry import FloatArray

if TYPE_CHECKING:
    from astralis_des.kernel.contracts import Host
    from astralis_des.physics.engine import Engine

AHEAD = math.radians(25.0)  # half-angle of the lidar sector a UGV slows down for
SLOW_AT = 1.5  # m from the lidar: nearer than this ahead, a UGV slows down ...
STOP_AT = 0.7  # m: ... to CREEP of its speed here
CREEP = 0.3
CULL = 0.5  # no frame is rendered when the target, unhidden (or hidden only by walls and
# slabs), would show less than this share of the pixels a detection needs (the shared
# detection model's prediction)


@dataclass
class SensorClock:
    """Wall seconds and calls per sensor."""

    seconds: dict[str, float] = field(default_factory=dict)
    calls: dict[str, int] = field(default_factory=dict)

    def timed(self, name: str) -> _Timed:
        """A context that adds its wall time and one call to ``name``'s."""
        return _Timed(self, name)


class _Timed:
    """One timed sensor call: a plain class, not ``contextlib.contextmanager`` (whose
    generator costs more than an IMU's reading; sensors are timed thousands of times a run)."""

    __slots__ = ("clock", "name", "t0")

    def __init__(self, clock: SensorClock, name: str) -> None:
        self.clock, self.name, self.t0 = clock, name, 0.0

    def __enter__(self) -> None:
        self.t0 = time.perf_counter()

    def __exit__(self, *exc: object) -> None:
        clock, name = self.clock, self.name
        clock.seconds[name] = clock.seconds.get(name, 0.0) + time.perf_counter() - self.t0
        clock.calls[name] = clock.calls.get(name, 0) + 1


class Eyes:
    """A robot's camera: full resolution to detect, half to keep frames."""

    def __init__(self, cosim: Engine, robot: Robot, spec: CameraSpec, view: View,
                 offscreen: Offscreen) -> None:
        body = cosim.drivers[robot.id].body
        mount = _mount(cosim, robot.id)
        self.spec, self.view = spec, view
        far = 2.0 * view.reach + 1.0  # past any detection, off-axis views included
        k = Intrinsics(spec.width, spec.height, view.fov_deg, far=far)
        self.full = Camera(cosim.client, body, k, mount, view.pitch_deg, offscreen=offscreen)
        small = Intrinsics(max(spec.width // 2, 1), max(spec.height // 2, 1), view.fov_deg,
                           far=far)
        self.small = Camera(cosim.client, body, small, mount, view.pitch_deg,
                            offscreen=offscreen)
        self.next_keep = 0.0


class Perception:
    """Cameras, lidars and IMUs of a physics run."""

    def __init__(self, cosim: Engine, sim: Host) -> None:
        self.cosim, self.env = cosim, sim.env
        self._host = sim  # asked at each look whether its outputs record the kept frames
        self.clock = SensorClock()
        self.frames: list[KeptFrame] = []
        self.scans: list[KeptScan] = []
        self.imu_traces: dict[str, ImuTrace] = {}
        self.eyes: dict[str, Eyes] = {}
        self.lidars: dict[str, tuple[Lidar2D, LidarSpec]] = {}
        self.lidars3d: dict[str, tuple[Lidar3D, Lidar3dSpec]] = {}
        self.clouds: list[KeptCloud] = []
        self.imus: dict[str, tuple[Imu, ImuSpec]] = {}
        seed = sim.mission.spec.seed
        offscreen = Offscreen(cosim.client, [d.body for d in cosim.drivers.values()])
        for index, member in enumerate(sim.mission.spec.team):
            robot, sensors = sim.robots[member.id], member.sensor_set
            body = cosim.drivers[member.id].body
            if sensors.camera is not None and robot.view is not None:
                self.eyes[member.id] = Eyes(cosim, robot, sensors.camera, robot.view, offscreen)
            if sensors.lidar is not None:
                spec = sensors.lidar
                self.lidars[member.id] = (Lidar2D(
                    cosim.client, body, _mount(cosim, member.id), spec.beams, spec.range,
                    noise_std=spec.noise_std, rng=stream(seed, "sensing", 1, index),
                    start_offset=KIND_DEFAULTS[member.kind].lidar_offset), spec)
            if sensors.lidar3d is not None:
                s3 = sensors.lidar3d
                self.lidars3d[member.id] = (Lidar3D(
                    cosim.client, body, channels=s3.channels, vertical_fov=s3.vertical_fov,
                    resolution=s3.resolution, range_max=s3.range, noise_std=s3.noise_std,
                    rng=stream(seed, "sensing", 3, index),
                    start_offset=KIND_DEFAULTS[member.kind].lidar_offset,
                    mount=tuple(_mount(cosim, member.id))), s3)
            if sensors.imu is not None:
                spec_i = sensors.imu
                self.imus[member.id] = (Imu(
                    cosim.client, body, spec_i.accel_noise, spec_i.gyro_noise,
                    spec_i.accel_bias, spec_i.gyro_bias, stream(seed, "sensing", 2, index)),
                    spec_i)
                self.imu_traces[member.id] = ImuTrace()

    # -- cameras -----------------------------------------------------------------------------
    def watch(self, robot: Robot, done: simpy.Event) -> simpy.Process:
        """A process that looks ahead while ``robot`` moves; its value is the first
        sighting, or None when the motion ends unseen."""
        return self.env.process(self._watch(robot, done))

    def _watch(self, robot: Robot,
               done: simpy.Event) -> Generator[simpy.Event, Any, Sighting | None]:
        eyes = self.eyes.get(robot.id)
        if eyes is None:
            return None
        track = robot.motion
        while not done.triggered and robot.motion is track:
            hit = self._look(robot, eyes, [self._travel_yaw(robot, eyes)])
            if hit is not None:
                return hit
            yield self.env.timeout(1.0 / eyes.spec.rate)
        return None

    def look(self, robot: Robot) -> Sighting | None:
        """One look from where the robot waits: around, for a camera that pans."""
        eyes = self.eyes.get(robot.id)
        if eyes is None:
            return None
        if not eyes.view.gimbal:
            return self._look(robot, eyes, [None])
        return self._look(robot, eyes, list(look_headings(eyes.view, robot.heading)))

    def _travel_yaw(self, robot: Robot, eyes: Eyes) -> float | None:
        """A gimbal turns to the direction of travel (kept while hovering); a body camera
        turns with the body (None)."""
        if not eyes.view.gimbal:
            return None
        ahead = self.cosim.drivers[robot.id].heading_vector()
        if float(np.hypot(*ahead)) > 1e-3:
            robot.heading = math.atan2(float(ahead[1]), float(ahead[0]))
        return robot.heading

    def _look(self, robot: Robot, eyes: Eyes, yaws: list[float | None]) -> Sighting | None:
        now = self.env.now
        if eyes.spec.record_rate > 0 and now >= eyes.next_keep and self._host.recorded:
            eyes.next_keep = now + 1.0 / eyes.spec.record_rate
            with self.clock.timed("camera"):
                self._keep(robot.id, eyes.small.capture(now, yaws[0]), detection=False)
        body, centre, size = self.cosim.target_now(now)
        one = np.zeros(1, dtype=int)
        for yaw in yaws:
            with self.clock.timed("camera_cull"):
                eye, rotation = eyes.full.pose(yaw)
                heading = math.atan2(rotation[1, 2], rotation[0, 2])
                inside, _ = in_frame(eyes.view, eye[None, :], np.array([heading]),
                                     centre[None, :], np.asarray(size), one, one)
                # would it show enough pixels if nothing hid it, and then if only the walls
                # and slabs did (exact boxes in both fidelities; furniture is left to the
                # render)? A target in the next room costs no frame.
                worth = len(inside) > 0 and all(predict_pixels(
                    eyes.view, eye[None, :], np.array([heading]), centre[None, :], size,
                    sight)[0] >= CULL * eyes.view.min_pixels
                    for sight in (None, self.cosim.world.line_of_sight))
            if not worth:
                continue
            with self.clock.timed("camera"):
                frame = eyes.full.capture(now, yaw)
                hit = self._detect(frame, body, eyes, centre)
            if hit is not None:
                self._keep(robot.id, frame, detection=True, step=2)
                return hit
        return None

    def _detect(self, frame: Frame, body: int, eyes: Eyes, centre: FloatArray) -> Sighting | None:
        mask = frame.segmentation == body
        if eyes.view.range is not None:
            mask &= frame.depth <= eyes.view.range
        pixels = int(np.count_nonzero(mask))
        if pixels < eyes.spec.min_pixels:
            return None
        estimate = frame.points_where(mask).mean(axis=0)
        eye = frame.pose[0]
        return Sighting(0.0, _xyz(eye), _xyz(centre), float(np.linalg.norm(centre - eye)),
                        _xyz(estimate), float(np.linalg.norm(estimate - centre)), pixels)

    def _keep(self, robot_id: str, frame: Frame, detection: bool, step: int = 1) -> None:
        k = frame.intrinsics
        small = Intrinsics(k.width // step, k.height // step, k.fov_deg, k.near, k.far)
        metres = frame.depth[::step, ::step]
        depth = np.where(np.isfinite(metres), np.clip(metres * 1000.0, 0, 65535), 0.0
                         ).round().astype(np.uint16)
        segmentation = (frame.segmentation[::step, ::step] + 1).astype(np.uint16)
        self.frames.append(KeptFrame(robot_id, frame.time, frame.rgb[::step, ::step].copy(),
                                     depth, segmentation, frame.pose[0], frame.pose[1], small,
                                     detection))

    # -- lidars and IMUs ---------------------------------------------------------------------
    def moving(self, robot: Robot, done: simpy.Event) -> None:
        """Start the robot's lidar and IMU for a motion that ends with ``done``, or stops
        being the robot's motion (halted for a fault, or a new one in its place: ``done``
        of a halted motion never fires)."""
        track = robot.motion
        if robot.id in self.lidars:
            self.env.process(self._scan(robot, done, track))
        if robot.id in self.imus:
            self.env.process(self._read(robot, done, track))
        if robot.id in self.lidars3d:
            self.env.process(self._sweep(robot, done, track))

    @staticmethod
    def _on(robot: Robot, done: simpy.Event, track: object) -> bool:
        """Is the motion ``track`` (ending with ``done``) still going?"""
        return not done.triggered and robot.motion is track

    def _sweep(self, robot: Robot, done: simpy.Event,
               track: object) -> Generator[simpy.Event, Any, None]:
        """The 3-D lidar at its rate while the robot moves; every so often a sweep kept."""
        lidar, spec = self.lidars3d[robot.id]
        keep_every = max(1, round(spec.rate / spec.record_rate)) if spec.record_rate else 0
        count = 0
        while self._on(robot, done, track):
            with self.clock.timed("lidar3d"):
                scan = lidar.scan(self.env.now)
            if keep_every and count % keep_every == 0:
                hit = np.isfinite(scan.ranges)
                self.clouds.append(KeptCloud(robot.id, self.env.now, scan.points[hit],
                                             scan.hit_ids[hit]))
            count += 1
            yield self.env.timeout(1.0 / spec.rate) | done

    def _scan(self, robot: Robot, done: simpy.Event,
              track: object) -> Generator[simpy.Event, Any, None]:
        lidar, spec = self.lidars[robot.id]
        driver = self.cosim.drivers[robot.id]
        keep_every = max(1, round(spec.rate / spec.record_rate)) if spec.record_rate else 0
        count = 0
        while self._on(robot, done, track):
            with self.clock.timed("lidar"):
                scan = lidar.scan(self.env.now)
                # the sector it slows down for looks the way it is headed (to its pursued
                # point), not at a wall it is turning away from
                way = driver.heading_vector()
                off = math.atan2(way[1], way[0]) - lidar.heading() if way.any() else 0.0
                ahead = np.abs(np.remainder(scan.angles - off + math.pi, math.tau) - math.pi) \
                    <= AHEAD
                nearest = float(scan.ranges[ahead].min()) if ahead.any() else math.inf
            share = min(max((nearest - STOP_AT) / (SLOW_AT - STOP_AT), CREEP), 1.0)
            driver.slow_down(share)
            if keep_every and count % keep_every == 0:
                hits = scan.points[np.isfinite(scan.ranges)]
                self.scans.append(KeptScan(robot.id, self.env.now, hits))
            count += 1
            yield self.env.timeout(1.0 / spec.rate) | done
        if done.triggered or robot.motion is None:  # not a new motion's, which scans itself
            driver.slow_down(1.0)

    def _read(self, robot: Robot, done: simpy.Event,
              track: object) -> Generator[simpy.Event, Any, None]:
        imu, spec = self.imus[robot.id]
        trace = self.imu_traces[robot.id]
        imu._velocity = None  # a new motion: no difference across the pause before it
        last = self.cosim.t
        ticks = max(1, round(1.0 / (spec.rate * self.cosim.period)))
        while self._on(robot, done, track):
            # a plain timeout, not one or ``done``: a condition costs more than the reading,
            # and a motion that ended meanwhile reads nothing either way
            yield self.env.timeout(ticks * self.cosim.period)
            dt = self.cosim.t - last
            if dt <= 1e-9 or not self._on(robot, done, track):
                continue
            last = self.cosim.t
            with self.clock.timed("imu"):
                trace.readings.append(imu.read(dt, self.env.now))
            trace.times.append(self.env.now)


def _mount(cosim: Engine, robot_id: str) -> FloatArray:
    """Where the robot's sensors sit in its body frame: at the pose the fidelity reports."""
    driver = cosim.drivers[robot_id]
    base, quat = cosim.client.call("getBasePositionAndOrientation", driver.body)
    rotation = np.array(cosim.client.call("getMatrixFromQuaternion", quat)).reshape(3, 3)
    out: FloatArray = rotation.T @ (driver.position() - np.asarray(base))
    return out


def _xyz(p: FloatArray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))
