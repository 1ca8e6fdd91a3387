"""What each agent kind is by default: speed, camera, height of its sensor, sensor set."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class CameraDefaults:
    """A kind's camera when the mission does not say: its reach and where it looks."""

    range: float | None  # m: a cap on the detector's reach; None: the pixels decide
    fov_deg: float  # vertical field of view
    pitch_deg: float  # 0 forward, 90 straight down
    gimbal: bool  # levelled and turned to the direction of travel (else fixed to the body)
    look_around: bool  # while waiting in place it pans a full turn (a hovering UAV, a person)


@dataclass(frozen=True)
class KindDefaults:
    speed: float  # m/s, cruise
    camera: CameraDefaults
    height: float  # m above the floor of its sensor (a UAV's flight altitude indoors)
    distance: str  # Eq. 1's distance for this kind: "l2" or "manhattan"
    sensors: tuple[str, ...]  # what it carries when the mission names no sensors
    radius: float  # m: the disc round its centre that planners keep clear of walls
    accel: float | None = None  # m/s^2 speeding up and slowing down; None for a walker
    turn_rate: float | None = None  # rad/s turning on the spot (a non-holonomic robot)
    footprint: tuple[float, float] | None = None  # m, length and width of a long body
    rest: float | None = None  # m above the floor of its sensor when landed; None: it walks
    # or drives (its sensor is always at ``height``)

    @property
    def flies(self) -> bool:
        """Whether it takes off and lands (a UAV): it has a resting height."""
        return self.rest is not None

    @property
    def length(self) -> float:
        """The longest side of its body seen from above (its footprint, else its disc)."""
        return max(self.footprint) if self.footprint is not None else 2 * self.radius

    @property
    def swept_radius(self) -> float | None:
        """The circle a body with a footprint sweeps turning on the spot (its half-diagonal)."""
        if self.footprint is None:
            return None
        return math.hypot(self.footprint[0] / 2, self.footprint[1] / 2)


UAV_BODY_HALF_HEIGHT = 0.06  # m: half the hexacopter's body (its collision cylinder)
UAV_FLIGHT_HEIGHT = 1.975  # m: the default world's flight height (see world.flight)
UAV_REST = 0.07  # m: its centre standing on the floor (half its body and a centimetre)
CLIMB_SPEED = 1.0  # m/s: a UAV taking off or landing

KIND_DEFAULTS: dict[str, KindDefaults] = {
    # A gimballed camera 75 degrees down: at 2 m over the floor it sees a strip about 4 m
    # wide below the craft, mostly ahead of it. Indoors it flies over the heads of standing
    # people and under the door lintels (:func:`astralis_des.world.flight.flight_height`):
    # ``height`` is the flight height where the world sets none. It starts and ends landed.
    "uav": KindDefaults(speed=1.5, camera=CameraDefaults(None, 90.0, 75.0, True, True),
                        height=UAV_FLIGHT_HEIGHT, distance="l2", sensors=("camera", "imu"),
                        radius=0.3, accel=2.0, rest=UAV_REST),
    # A forward camera on the body, and a lidar the local planner slows down for.
    "ugv": KindDefaults(speed=1.0, camera=CameraDefaults(None, 60.0, 0.0, False, False),
                        height=0.5, distance="manhattan", sensors=("camera", "lidar", "imu"),
                        radius=0.35, accel=1.0, turn_rate=1.0,
                        footprint=(1.01, 0.69)),  # the Husky
    # A person's eyes: a wide view a little down, ahead of where they walk.
    "human": KindDefaults(speed=1.2, camera=CameraDefaults(None, 90.0, 15.0, True, True),
                          height=1.6, distance="manhattan", sensors=("camera",), radius=0.25),
}
KINDS = tuple(KIND_DEFAULTS)
LARGEST = max(KINDS, key=lambda k: KIND_DEFAULTS[k].length)  # the kind of the longest body
TARGET_HEIGHT = 0.5  # m above the floor: the centre of a sitting or laying avatar
TARGET_SIZE = (0.5, 0.5, 2 * TARGET_HEIGHT)  # m: the box of a sitting avatar
TARGET_FACE = TARGET_SIZE[1] * TARGET_SIZE[2]  # m^2: its side, seen square on
