"""Sensors that read only the pose: GNSS, barometer and magnetometer, in both fidelities
(:mod:`.models`: what each reads; :mod:`.run`: a run's sensors, read from the robots' past
poses)."""

from astralis_des.navsensors.models import (
    Barometer,
    Gnss,
    Magnetometer,
    Origin,
    Readings,
    altitude_of,
    pressure_at,
    sky_openness,
    yaw_rotation,
)
from astralis_des.navsensors.run import BodySamples, PoseSensors, motion_poses, site_origin

__all__ = ["Barometer", "BodySamples", "Gnss", "Magnetometer", "Origin", "PoseSensors",
           "Readings", "altitude_of", "motion_poses", "pressure_at", "site_origin",
           "sky_openness", "yaw_rotation"]
