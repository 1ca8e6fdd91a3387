"""The sensors a team member carries, and the site's place on the Earth (mission schema)."""

from __future__ import annotations

from typing import Any

from pydantic import Field, model_validator

from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.mission.types import Finite, NonNegativeFloat, PositiveFloat, Strict, Vec3


class CameraSpec(Strict):
    """A pinhole camera: RGB, depth and segmentation (physics), or its frustum (kinematic).

    Unset geometry comes from the robot's kind (``astralis_des.kinds``)."""

    width: int = Field(320, gt=0, le=4096, description="pixels")
    height: int = Field(240, gt=0, le=4096, description="pixels")
    fov_deg: float | None = Field(None, gt=0, lt=180, description="vertical field of view")
    range: PositiveFloat | None = Field(None, description="m: farther is not detected")
    pitch_deg: float | None = Field(None, ge=-90, le=90,
                                    description="0 forward, 90 straight down")
    min_pixels: int = Field(40, ge=1, description="target pixels a detection needs (physics)")
    rate: PositiveFloat = Field(
        4.0, le=60, description="looks per s while searching (physics): a frame is rendered "
        "when the target's box may be in view, else the look costs a frustum test")
    record_rate: NonNegativeFloat = Field(
        0.5, le=10, description="frames per s kept for the recording, rendered at half "
        "resolution (physics); 0: only the frame of a detection")
    position_noise: NonNegativeFloat = Field(
        0.03, description="kinematic fidelity: the estimate's error per axis, a share of the "
        "distance (physics estimates from the depth pixels)")


class LidarSpec(Strict):
    """A 2-D lidar in the robot's horizontal plane (physics fidelity)."""

    beams: int = Field(360, ge=1, le=4096)
    range: PositiveFloat = 30.0
    rate: PositiveFloat = Field(10.0, le=60, description="scans per s while moving")
    noise_std: NonNegativeFloat = Field(0.01, description="m, range noise")
    record_rate: NonNegativeFloat = Field(1.0, le=60, description="scans per s kept for the "
                                          "recording")


class Lidar3dSpec(Strict):
    """A spinning multi-channel lidar (physics fidelity), levelled, turning with the body's
    heading; the defaults are a 16-channel unit's."""

    channels: int = Field(16, ge=1, le=128)
    vertical_fov: tuple[float, float] = Field(
        (-15.0, 15.0), description="degrees: the lowest and the highest channel's elevation")
    resolution: float = Field(0.2, ge=0.05, le=10.0, description="degrees between azimuths")
    range: PositiveFloat = Field(100.0, le=1000.0, description="m")
    rate: PositiveFloat = Field(10.0, le=20, description="sweeps per s while moving")
    noise_std: NonNegativeFloat = Field(0.01, le=10.0, description="m, range noise")
    record_rate: NonNegativeFloat = Field(1.0, le=20, description="sweeps per s kept for "
                                          "the recording")

    @model_validator(mode="after")
    def _fov(self) -> Lidar3dSpec:
        low, high = self.vertical_fov
        if not -90.0 <= low < high <= 90.0:
            raise ValueError(f"vertical_fov must be [low, high] with -90 <= low < high <= 90 "
                             f"degrees (got [{low:g}, {high:g}])")
        return self


class ImuSpec(Strict):
    """An IMU: specific force and angular rate, with noise and constant biases (physics)."""

    rate: PositiveFloat = Field(20.0, description="readings per s while moving, rounded to "
                                "whole controller ticks; at most the physics control_rate")
    accel_noise: NonNegativeFloat = 0.02
    gyro_noise: NonNegativeFloat = 0.002
    accel_bias: Vec3 = (0.0, 0.0, 0.0)
    gyro_bias: Vec3 = (0.0, 0.0, 0.0)


class GnssSpec(Strict):
    """A GNSS receiver: a fix in latitude, longitude and altitude from the site's geodetic
    origin (``site``), degraded and then lost as walls, slabs and roofs hide the sky."""

    rate: PositiveFloat = Field(1.0, le=50, description="fixes per s")
    horizontal_noise: NonNegativeFloat = Field(1.5, le=100,
                                               description="m, one sigma under an open sky")
    vertical_noise: NonNegativeFloat = Field(3.0, le=100,
                                             description="m, one sigma under an open sky")
    satellites: int = Field(12, ge=0, le=64, description="satellites seen under an open sky; "
                            "a share of them as the sky closes, no fix under 4")
    degraded_below: float = Field(0.6, gt=0, le=1, description="open share of the sky "
                                  "under which the noise grows (as its inverse square)")


class BarometerSpec(Strict):
    """A barometer: ISA pressure at the site's altitude plus the height, white noise and a
    drifting bias (first-order Gauss-Markov), and the altitude it implies."""

    rate: PositiveFloat = Field(10.0, le=100, description="readings per s")
    noise: NonNegativeFloat = Field(2.7, le=1000, description="Pa, white (about 0.23 m)")
    drift: NonNegativeFloat = Field(10.0, le=1000,
                                    description="Pa, the bias's steady-state sigma")
    drift_time: PositiveFloat = Field(3600.0, description="s, the bias's correlation time")


class MagnetometerSpec(Strict):
    """A magnetometer: the site's magnetic field in the body frame, with noise and a
    constant bias, and the heading it implies."""

    rate: PositiveFloat = Field(20.0, le=200, description="readings per s")
    noise: NonNegativeFloat = Field(0.3, le=100, description="microtesla, white")
    bias: tuple[Finite, Finite, Finite] = Field(
        (0.0, 0.0, 0.0), description="microtesla, body frame (forward, left, up)")


class SiteSpec(Strict):
    """Where the site lies on the Earth: its (0, 0, 0) in WGS 84, and the Earth's magnetic
    field there. The default is the Autzen Stadium area of Eugene, Oregon (where the
    repository's aerial scan was taken), its field from the World Magnetic Model 2025 for
    2026 (declination about 14.6 degrees east, inclination 67 degrees, 51.5 microtesla)."""

    latitude: float = Field(44.0582, ge=-90, le=90, description="degrees north")
    longitude: float = Field(-123.0684, ge=-180, le=180, description="degrees east")
    altitude: float = Field(130.0, ge=-500, le=9000,
                            description="m above the WGS 84 ellipsoid, of the ground")
    magnetic_field: tuple[Finite, Finite, Finite] = Field(
        (19.47, 5.07, 47.41), description="microtesla: north, east, down")


class SensorsSpec(Strict):
    """What a robot carries. A member without ``sensors`` gets its kind's set
    (UAV: camera and IMU; UGV: camera, lidar and IMU; human: camera); one that names
    sensors gets a camera unless ``camera: null``, and only the lidar and IMU it names."""

    camera: CameraSpec | None = Field(default_factory=CameraSpec)
    lidar: LidarSpec | None = None
    lidar3d: Lidar3dSpec | None = None
    imu: ImuSpec | None = None
    gnss: GnssSpec | None = None
    barometer: BarometerSpec | None = None
    magnetometer: MagnetometerSpec | None = None
    plugins: dict[str, dict[str, Any]] = Field(
        default_factory=dict, description="sensors added by name (registered in "
        "astralis_des.plugins.SENSORS), each with its parameters: {name: {param: value}}")


SENSORS = ("camera", "lidar", "lidar3d", "imu", "gnss", "barometer", "magnetometer")
POSE_SENSORS = ("gnss", "barometer", "magnetometer")  # read the pose alone: both fidelities


def carries(kind: str) -> tuple[str, ...]:
    """The sensors ``kind`` can carry (its record's, else every one)."""
    return KIND_DEFAULTS[kind].carries or SENSORS


_DEFAULT_SPECS = {"camera": CameraSpec(), "lidar": LidarSpec(), "imu": ImuSpec()}
