"""Kinematic fidelity: a motion takes path length / speed; poses are interpolated on demand."""

from __future__ import annotations

import simpy

from astralis_des.cosim import COSIMS
from astralis_des.kernel.robot import Motion, Robot


@COSIMS.register("kinematic")
class KinematicCoSim:
    def __init__(self, env: simpy.Environment) -> None:
        self.env = env

    def execute(self, robot: Robot, motion: Motion) -> simpy.Event:
        """An event that succeeds with the motion when the robot arrives."""
        robot.begin(motion, self.env.now)
        return self.env.timeout(motion.duration, value=motion)

    def dwell(self, robot: Robot, seconds: float) -> simpy.Event:
        robot.halt(self.env.now)
        return self.env.timeout(seconds)

    def halt(self, robot: Robot) -> None:
        robot.halt(self.env.now)

    def close(self) -> None:
        """Nothing to release; the physics fidelity frees its client here."""
