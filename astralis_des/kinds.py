"""What each agent kind is by default: speed, sensing reach and height of its sensor."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class KindDefaults:
    speed: float  # m/s, cruise
    detection_radius: float  # m, reach of its camera for the geometric detection model
    height: float  # m above the floor of its sensor (a UAV's flight altitude indoors)
    distance: str  # Eq. 1's distance for this kind: "l2" or "manhattan"
    accel: float | None = None  # m/s^2 speeding up and slowing down; None for a walker
    turn_rate: float | None = None  # rad/s turning on the spot (a non-holonomic robot)


KIND_DEFAULTS: dict[str, KindDefaults] = {
    "uav": KindDefaults(speed=1.5, detection_radius=2.0, height=1.5, distance="l2",
                        accel=2.0),
    "ugv": KindDefaults(speed=1.0, detection_radius=6.0, height=0.5, distance="manhattan",
                        accel=1.0, turn_rate=1.0),
    "human": KindDefaults(speed=1.2, detection_radius=3.0, height=1.6, distance="manhattan"),
}
KINDS = tuple(KIND_DEFAULTS)
TARGET_HEIGHT = 0.5  # m above the floor: the centre of a sitting or laying avatar
