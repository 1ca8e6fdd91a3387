"""Kinematic fidelity: a motion takes path length / speed; poses are interpolated on demand."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import simpy

from astralis_des.kernel.contracts import BodyPose, CoSim, Host, MotionOutcome, Perceived, Sensor
from astralis_des.kernel.robot import Motion, Robot
from astralis_des.plugins import COSIMS

if TYPE_CHECKING:
    from astralis_des.detection import Sighting


ARRIVED = MotionOutcome(True, "arrived")


@COSIMS.register("kinematic")
class KinematicCoSim:
    def __init__(self, sim: Host) -> None:
        self.env = sim.env

    @property
    def body_pose(self) -> BodyPose | None:
        """No simulated body: poses come from the motions."""
        return None

    @property
    def perception(self) -> Perceived | None:
        """No sensors of its own: sensing is geometric (the run's ``Sensor``)."""
        return None

    def execute(self, robot: Robot, motion: Motion) -> simpy.Event:
        """An event that succeeds with the motion's outcome when the robot arrives."""
        robot.begin(motion, self.env.now)
        return self.env.timeout(motion.duration, value=ARRIVED)

    def watch(self, robot: Robot, motion: Motion, sensor: Sensor,
              done: simpy.Event) -> simpy.Event:
        """An event that succeeds with the first sighting along the motion (never if none)."""
        hit = sensor.first_sighting(robot, motion)
        return self.env.timeout(hit.t, value=hit) if hit is not None else self.env.event()

    def look(self, robot: Robot, sensor: Sensor) -> Sighting | None:
        """What the robot's camera sees from where it stands now (around, if it pans)."""
        return sensor.sighting_from(robot, robot.position(self.env.now), self.env.now)

    def face(self, robot: Robot, heading: float) -> simpy.Event:
        """Turn on the spot to ``heading`` (at once for a robot that needs not turn)."""
        robot.halt(self.env.now)
        turn = abs(math.remainder(heading - robot.heading, math.tau))
        robot.heading = heading
        seconds = turn / robot.turn_rate if robot.turn_rate else 0.0
        return self.env.timeout(seconds, value=ARRIVED)

    def dwell(self, robot: Robot, seconds: float) -> simpy.Event:
        robot.halt(self.env.now)
        return self.env.timeout(seconds)

    def halt(self, robot: Robot) -> None:
        robot.halt(self.env.now)

    def recover(self, robot: Robot) -> None:
        """A faulted robot is put back in service (nothing to do without a body)."""

    def close(self) -> None:
        """Nothing to release; the physics fidelity frees its client here."""


if TYPE_CHECKING:  # the contract, as mypy checks it
    _FIDELITY: Callable[[Host], CoSim] = KinematicCoSim
