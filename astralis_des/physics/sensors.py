"""Simulated sensors on PyBullet bodies: a pinhole camera, a planar lidar and an IMU.

Frames: a body's frame is PyBullet's (x forward, y left, z up). The camera frame is the
computer-vision one (x right, y down, z forward along the optical axis); a pixel ``(u, v)`` is
``(column, row)`` with row 0 at the top, and an ideal pixel ``i`` covers ``[i, i + 1)``.
TinyRenderer rasterises half a pixel off that: the centre of column ``c`` is at ``u = c`` and
of row ``r`` at ``v = r + 1`` (measured on box edges, any image size), so a :class:`Frame`
carries its renderer's pixel centre. Noise is drawn only from the ``numpy.random.Generator``
a sensor is given.
"""

from __future__ import annotations

import logging
import math
from contextlib import nullcontext
from dataclasses import dataclass, field

import numpy as np
import pybullet as pb
from numpy.typing import NDArray

from astralis_des.kernel.perceived import ImuReading, Intrinsics
from astralis_des.physics.client import GRAVITY, PhysicsClient, beams_near_bodies
from astralis_des.physics.offscreen import Offscreen
from astralis_des.world.geometry import FloatArray

__all__ = ["Camera", "Frame", "Imu", "ImuReading", "Intrinsics", "Lidar2D", "Scan"]

log = logging.getLogger(__name__)
Vec3 = tuple[float, float, float] | FloatArray
IntArray = NDArray[np.int32]
NO_BODY = -1  # segmentation and hit id where nothing was seen
# (u, v) of pixel (0, 0)'s centre: TinyRenderer's, measured; the ideal pinhole's is (0.5, 0.5)
PIXEL_CENTRE = {pb.ER_TINY_RENDERER: (0.0, 1.0)}
_DOWN = (0.0, 0.0, -GRAVITY)  # gravity's acceleration: an IMU at rest reads its opposite


def _body_pose(client: PhysicsClient, body: int) -> tuple[FloatArray, FloatArray]:
    """Position and rotation matrix (world from body) of a body's base."""
    pos, quat = client.base_pose(body)
    rotation = pb.getMatrixFromQuaternion(quat, physicsClientId=client.id)
    return np.array(pos), np.array(rotation).reshape(3, 3)


def _need_rng(noise: float, rng: np.random.Generator | None, what: str) -> None:
    """Refuse noise without an explicit generator: the global RNG would break determinism."""
    if noise > 0 and rng is None:
        raise ValueError(f"{what} has noise but no rng: pass a numpy.random.Generator")


@dataclass
class Frame:
    """One rendered image: colour, metric depth and which body each pixel shows."""

    rgb: NDArray[np.uint8]  # (H, W, 3)
    depth: FloatArray  # (H, W) metres along the optical axis; inf where nothing was rendered
    segmentation: IntArray  # (H, W) body unique ids; -1 where nothing was rendered
    time: float
    pose: tuple[FloatArray, FloatArray]  # eye position, rotation world_from_camera
    intrinsics: Intrinsics
    pixel_centre: tuple[float, float] = (0.5, 0.5)  # (u, v) of pixel (0, 0)'s centre

    def pixels_of(self, body: int) -> int:
        """How many pixels show ``body``: a detector's size-in-image test."""
        return int(np.count_nonzero(self.segmentation == body))

    def uv_of(self, body: int) -> FloatArray:
        """``(N, 2)`` pixel coordinates of ``body``'s pixels' centres, comparable to ``project``."""
        rows, cols = np.nonzero(self.segmentation == body)
        return np.column_stack([cols + self.pixel_centre[0], rows + self.pixel_centre[1]])

    def points_of(self, body: int) -> FloatArray:
        """``(N, 3)`` world points of ``body``'s pixels, back-projected from the depth."""
        return self.points_where(self.segmentation == body)

    def points_where(self, mask: NDArray[np.bool_]) -> FloatArray:
        """``(N, 3)`` world points of the pixels in ``mask``, back-projected from the depth."""
        rows, cols = np.nonzero(mask)
        k, z = self.intrinsics, self.depth[rows, cols]
        camera = np.column_stack([(cols + self.pixel_centre[0] - k.cx) * z / k.fx,
                                  (rows + self.pixel_centre[1] - k.cy) * z / k.fy, z])
        position, rotation = self.pose
        out: FloatArray = camera @ rotation.T + position
        return out


class Camera:
    """A camera fixed to a body: mount offset in the body frame, pitched down on a gimbal."""

    def __init__(self, client: PhysicsClient, body: int, intrinsics: Intrinsics,
                 mount: Vec3 = (0.0, 0.0, 0.0), pitch_deg: float = 0.0,
                 renderer: int = pb.ER_TINY_RENDERER, hide_body: bool = True,
                 offscreen: Offscreen | None = None) -> None:
        """``offscreen``: other bodies to leave out of a frame they cannot show in."""
        self.client, self.body, self.intrinsics, self.renderer = client, body, intrinsics, renderer
        self.offscreen = offscreen
        self.mount = np.asarray(mount, dtype=float)
        p = math.radians(pitch_deg)
        forward = np.array([math.cos(p), 0.0, -math.sin(p)])
        right = np.array([0.0, -1.0, 0.0])
        # camera axes (right, down, forward) as columns, in the body frame
        self.body_from_camera = np.column_stack([right, np.cross(forward, right), forward])
        k = intrinsics
        self.projection = client.call("computeProjectionMatrixFOV", k.fov_deg,
                                      k.width / k.height, k.near, k.far)
        # TinyRenderer skips fully transparent shapes. Colours are read once, here, because
        # getVisualShapeData reports one colour per link after a change: colour a body before
        # mounting a camera on it, or the capture restores the old colours.
        self._visuals: list[tuple[int, int, list[float]]] = []
        if hide_body:
            per_link: dict[int, int] = {}
            for shape in client.call("getVisualShapeData", body):
                index = per_link[shape[1]] = per_link.get(shape[1], -1) + 1
                self._visuals.append((shape[1], index, list(shape[7])))

    def pose(self, yaw: float | None = None) -> tuple[FloatArray, FloatArray]:
        """Eye position and rotation world_from_camera, from the body's current pose; with
        ``yaw``, on a gimbal: levelled and turned to that heading, the mount turned with it."""
        position, rotation = _body_pose(self.client, self.body)
        if yaw is not None:
            c, s = math.cos(yaw), math.sin(yaw)
            rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        return position + rotation @ self.mount, rotation @ self.body_from_camera

    def capture(self, time: float = 0.0, yaw: float | None = None) -> Frame:
        """Render the view now; the camera's own body is hidden so that it never blocks it."""
        eye, rotation = self.pose(yaw)
        view = self.client.call("computeViewMatrix", eye.tolist(), (eye + rotation[:, 2]).tolist(),
                                (-rotation[:, 1]).tolist())
        k = self.intrinsics
        self._paint(hidden=True)
        try:
            with nullcontext() if self.offscreen is None else \
                    self.offscreen.hidden(eye, rotation, k, skip=self.body):
                _, _, rgba, buffer, seg = self.client.call(
                    "getCameraImage", k.width, k.height, view, self.projection,
                    renderer=self.renderer)
        finally:
            self._paint(hidden=False)
        rgb = np.asarray(rgba, dtype=np.uint8).reshape(k.height, k.width, 4)[:, :, :3]
        segmentation = np.asarray(seg, dtype=np.int32).reshape(k.height, k.width)
        buffer = np.asarray(buffer, dtype=float).reshape(k.height, k.width)
        depth = k.far * k.near / (k.far - (k.far - k.near) * buffer)
        depth[segmentation < 0] = np.inf
        return Frame(np.ascontiguousarray(rgb), depth, segmentation, time, (eye, rotation), k,
                     PIXEL_CENTRE.get(self.renderer, (0.5, 0.5)))

    def _paint(self, hidden: bool) -> None:
        for link, index, rgba in self._visuals:
            self.client.call("changeVisualShape", self.body, link, shapeIndex=index,
                             rgbaColor=[0.0, 0.0, 0.0, 0.0] if hidden else rgba)


@dataclass
class Scan:
    """One lidar sweep; ``ranges`` is ``inf`` (and ``points`` nan, ``hit_ids`` -1) on no return."""

    ranges: FloatArray  # (beams,) metres from the sensor centre
    angles: FloatArray  # (beams,) radians from the body's heading, counter-clockwise
    points: FloatArray  # (beams, 3) world points at the measured ranges
    hit_ids: IntArray  # (beams,) body unique ids
    time: float = 0.0


class Lidar2D:
    """A levelled planar lidar: beams in the horizontal plane of the body's heading.

    Rays start ``start_offset`` out from the sensor centre so that they start outside the body
    (a ray starting inside a mesh hull costs several times more and hits the body), so
    nothing nearer than that is seen.
    """

    def __init__(self, client: PhysicsClient, body: int, mount: Vec3 = (0.0, 0.0, 0.0),
                 beams: int = 360, range_max: float = 30.0, range_min: float = 0.1,
                 noise_std: float = 0.01, rng: np.random.Generator | None = None,
                 start_offset: float = 0.5, near: float = 5.0) -> None:
        _need_rng(noise_std, rng, "Lidar2D")
        if not 0 <= start_offset < range_max:
            raise ValueError(f"start_offset {start_offset} m must lie in [0, range_max)")
        self.client, self.body, self.rng = client, body, rng
        self.mount = np.asarray(mount, dtype=float)
        self.range_max, self.range_min, self.noise_std = range_max, range_min, noise_std
        self.start_offset = start_offset
        self.near = near  # m: the first pass's reach (see ``scan``)
        self.angles: FloatArray = np.linspace(-math.pi, math.pi, beams, endpoint=False)
        self._warn_if_inside()

    def _warn_if_inside(self) -> None:
        """Rays starting inside the body are slow and may hit it: say so once, up front."""
        lo, hi = (np.array(c) for c in self.client.call("getAABB", self.body))
        origin, _ = self._frame()
        reach = np.abs(np.stack([lo - origin, hi - origin])).max(axis=0)
        if lo[2] <= origin[2] <= hi[2] and math.hypot(reach[0], reach[1]) > self.start_offset:
            log.warning("lidar rays of body %d may start inside it: start_offset %.2f m is "
                        "within its bounding box (%.2f m)", self.body, self.start_offset,
                        math.hypot(reach[0], reach[1]))

    def heading(self) -> float:
        """The body's heading (radians, counter-clockwise from x): the beams' zero."""
        _, rotation = _body_pose(self.client, self.body)
        return math.atan2(rotation[1, 0], rotation[0, 0])

    def _frame(self) -> tuple[FloatArray, FloatArray]:
        """Sensor centre and world directions of the beams."""
        position, rotation = _body_pose(self.client, self.body)
        a = self.angles + math.atan2(rotation[1, 0], rotation[0, 0])
        directions = np.column_stack([np.cos(a), np.sin(a), np.zeros_like(a)])
        return position + rotation @ self.mount, directions

    def scan(self, time: float = 0.0) -> Scan:
        """Cast every beam and add range noise to the returns.

        The static boxes (walls, slabs, obstacles, furniture) are a 2-D slab test in numpy
        (:mod:`astralis_des.physics.planar`). Bullet's ``rayTestBatch`` then follows only the
        beams that cross another body's bounding box (robots, avatars, the target, imported
        meshes), each only as far as its box (a box it meets there is the same hit). In two
        passes: to ``near`` metres, then on from there for the beams that found nothing; a
        ray's cost grows with the bounding boxes it crosses."""
        centre, directions = self._frame()
        start = self.start_offset
        ranges, ids = self.client.boxes.cast(centre, directions, start, self.range_max)
        ranges = np.minimum(ranges, self.range_max)  # a beam's reach: to its box or its end
        beams = beams_near_bodies(self.client, centre, directions, start, ranges)
        if len(beams):
            reach, along = ranges[beams], directions[beams]
            first = np.minimum(max(self.near, start), reach)
            found, at = self._cast(centre, along, start, first)
            beyond = np.flatnonzero((found < 0) & (first < reach))
            if len(beyond):
                found[beyond], at[beyond] = self._cast(centre, along[beyond], first[beyond],
                                                       reach[beyond])
            hit = found >= 0
            ranges[beams[hit]], ids[beams[hit]] = at[hit], found[hit]
        if self.noise_std > 0 and self.rng is not None:
            # drawn for every beam, so that the stream does not depend on what was hit
            ranges = ranges + self.rng.normal(0.0, self.noise_std, len(ranges))
        missed = (ids < 0) | (ranges < self.range_min)
        ranges[missed] = np.inf
        ids[missed] = NO_BODY
        points = centre + np.where(missed, np.nan, ranges)[:, None] * directions
        return Scan(ranges, self.angles.copy(), points, ids, time)

    def _cast(self, centre: FloatArray, directions: FloatArray, near: float | FloatArray,
              far: FloatArray) -> tuple[IntArray, FloatArray]:
        """Bullet's hits along the beams from ``near`` to ``far`` metres: the bodies hit (-1 for
        none) and their distances."""
        hits = self.client.call("rayTestBatch",
                                (centre + np.reshape(near, (-1, 1)) * directions).tolist(),
                                (centre + far[:, None] * directions).tolist())
        found = np.array([h[0] for h in hits], dtype=np.int32)
        return found, near + np.array([h[2] for h in hits]) * (far - near)


@dataclass
class Imu:
    """An IMU at a body's base: finite-difference acceleration, constant bias, white noise."""

    client: PhysicsClient
    body: int
    accel_std: float = 0.0  # m/s²
    gyro_std: float = 0.0  # rad/s
    accel_bias: Vec3 = (0.0, 0.0, 0.0)
    gyro_bias: Vec3 = (0.0, 0.0, 0.0)
    rng: np.random.Generator | None = None
    _velocity: tuple[float, float, float] | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        _need_rng(max(self.accel_std, self.gyro_std), self.rng, "Imu")
        self._biases = (tuple(float(v) for v in self.accel_bias),
                        tuple(float(v) for v in self.gyro_bias))

    def read(self, dt: float, time: float = 0.0) -> ImuReading:
        """A reading ``dt`` seconds after the previous one (the first assumes no acceleration).

        On plain floats (it is read 20 times a second: numpy's calls on 3-vectors cost more
        than their arithmetic), summed in the order of numpy's ``rotation.T @ v``."""
        _, quat = self.client.base_pose(self.body)
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = pb.getMatrixFromQuaternion(quat)
        linear, (wx, wy, wz) = self.client.base_velocity(self.body)
        vx, vy, vz = linear
        px, py, pz = linear if self._velocity is None else self._velocity
        self._velocity = (vx, vy, vz)
        # the acceleration less gravity's (_DOWN: 0, 0, -g), in the body frame, plus the bias
        gx, gy, gz = (vx - px) / dt - 0.0, (vy - py) / dt - 0.0, (vz - pz) / dt - _DOWN[2]
        (bx, by, bz), (cx, cy, cz) = self._biases
        force = np.array([r00 * gx + r10 * gy + r20 * gz + bx, r01 * gx + r11 * gy + r21 * gz + by,
                          r02 * gx + r12 * gy + r22 * gz + bz])
        rate = np.array([r00 * wx + r10 * wy + r20 * wz + cx, r01 * wx + r11 * wy + r21 * wz + cy,
                         r02 * wx + r12 * wy + r22 * wz + cz])
        if self.rng is not None:
            force = force + self.rng.normal(0.0, self.accel_std, 3)
            rate = rate + self.rng.normal(0.0, self.gyro_std, 3)
        return ImuReading(force, rate, time)
