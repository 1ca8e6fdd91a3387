"""What a fidelity's own sensors keep during a run, as plain records: camera frames, lidar
scans and clouds, IMU traces, and the pinhole a frame was taken with. The physics fidelity
(``astralis_des.physics.perception``) fills them; the sinks and the result read them through
:class:`astralis_des.kernel.contracts.Perceived`, which names these types."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from astralis_des.world.geometry import FloatArray


@dataclass(frozen=True)
class Intrinsics:
    """A pinhole camera with square pixels; ``fov_deg`` is the vertical field of view."""

    width: int
    height: int
    fov_deg: float
    near: float = 0.05
    far: float = 20.0

    @property
    def fy(self) -> float:
        return (self.height / 2) / math.tan(math.radians(self.fov_deg) / 2)

    @property
    def fx(self) -> float:
        return self.fy  # square pixels: PyBullet derives the horizontal fov from the aspect

    @property
    def cx(self) -> float:
        return self.width / 2

    @property
    def cy(self) -> float:
        return self.height / 2

    def project(self, points_camera: FloatArray) -> FloatArray:
        """``(N, 2)`` pixel coordinates ``(u, v)`` of ``(N, 3)`` points in the camera frame."""
        p = np.atleast_2d(np.asarray(points_camera, dtype=float))
        return np.column_stack([self.fx * p[:, 0] / p[:, 2] + self.cx,
                                self.fy * p[:, 1] / p[:, 2] + self.cy])


@dataclass
class ImuReading:
    """Specific force (m/s²) and angular rate (rad/s), both in the body frame."""

    specific_force: FloatArray
    angular_rate: FloatArray
    time: float = 0.0


@dataclass(frozen=True)
class KeptFrame:
    """A camera frame kept for the recording (half resolution)."""

    robot: str
    time: float
    rgb: NDArray[np.uint8]
    depth: NDArray[np.uint16]  # millimetres (to 65 m); 0 where nothing was rendered
    segmentation: NDArray[np.uint16]  # body id + 1; 0 where nothing was rendered
    eye: FloatArray
    rotation: FloatArray  # world_from_camera
    intrinsics: Intrinsics
    detection: bool


@dataclass(frozen=True)
class KeptScan:
    robot: str
    time: float
    points: FloatArray  # (M, 3): the returns only


@dataclass
class KeptCloud:
    robot: str
    time: float
    points: FloatArray  # (M, 3): the returns only
    ids: NDArray[np.int32]  # (M,): the body each return hit (its segmentation id)


@dataclass
class ImuTrace:
    times: list[float] = field(default_factory=list)
    readings: list[ImuReading] = field(default_factory=list)
