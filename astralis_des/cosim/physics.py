"""Physics fidelity: a PyBullet co-simulation behind the kinematic contract.

:class:`PhysicsCoSim` keeps the contract (start, turn, halt a robot's body, look, recover)
and the services the physics pieces (the local layer, making way, perception) ask of it
through :class:`~astralis_des.physics.engine.Engine`, and wires the parts: the scene's
bodies (:mod:`.physics_bodies`) and the stepper that advances the physics
(:mod:`.physics_stepper`).
"""

from __future__ import annotations

import shutil
import tempfile
import weakref
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import simpy

from astralis_des.cosim.physics_bodies import SceneBodies
from astralis_des.cosim.physics_stepper import Stepper
from astralis_des.detection import Sighting
from astralis_des.kernel.contracts import CoSim, Host, MotionOutcome, Sensor
from astralis_des.kernel.robot import Motion, Robot
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.drivers import DRIVERS, Driver, DriverClass, HumanDriver, PlacedDriver
from astralis_des.physics.hexacopter import write_urdf
from astralis_des.physics.lift import Lift, lifts_of
from astralis_des.physics.local import LocalLayer
from astralis_des.physics.perception import Perception
from astralis_des.physics.sensors import _body_pose
from astralis_des.physics.track import Track
from astralis_des.physics.ugv_driver import UgvDriver
from astralis_des.plugins import COSIMS
from astralis_des.world.geometry import FloatArray
from astralis_des.world.scene import Mover

CAP_FACTOR, CAP_SLACK = 2.0, 30.0  # a motion planned to take T s fails after 2 T + 30 s
TURN_CAP = 30.0  # s: a turn on the spot that takes longer has failed
RISE_AHEAD = 1.0  # s: a waiting UAV that a walking avatar reaches this soon has risen over it


@COSIMS.register("physics")
class PhysicsCoSim:
    """The physics fidelity: each robot's body driven in PyBullet behind the co-simulation
    contract, and what the physics pieces ask of the running simulation."""

    def __init__(self, sim: Host) -> None:
        spec = sim.mission.spec.physics
        self.env, self.log = sim.env, sim.log
        self.world = sim.world
        self.period = 1.0 / spec.control_rate
        self.client = PhysicsClient(sim.world, spec.dt, spec.rate // spec.control_rate,
                                    spec.solver_iterations)
        self._folder = Path(tempfile.mkdtemp(prefix="astralis-"))
        # removed at close, or when a simulation never ended is let go, or at the exit
        self._remove_folder = weakref.finalize(self, shutil.rmtree, self._folder,
                                               ignore_errors=True)
        urdf = write_urdf(spec.uav, self._folder)
        self.drivers: dict[str, Driver] = {
            rid: DRIVERS.get(robot.kind)(self.client, robot, spec, urdf)
            for rid, robot in sim.robots.items()}
        self.lifts = lifts_of(sim.world, self.client)
        for rid, driver in self.drivers.items():
            if isinstance(driver, UgvDriver):
                driver.lifts = self.lifts
                driver.column_busy = self._column_busy
            if isinstance(driver, PlacedDriver):
                driver.bodies_near = self._bodies_near(rid)
                driver.robot_of = {d.body: other for other, d in self.drivers.items()}
        self.robots = sim.robots
        self._navigator = sim.navigator
        self.active: dict[str, tuple[Robot, Track, simpy.Event]] = {}
        self.local = LocalLayer(self, list(sim.robots))
        # a mover's body is added where it is at physics time, which the stepper keeps; the
        # stepper steps the bodies, so it is built second and the clock is read late
        sleepers = [rid for rid, driver in self.drivers.items()
                    if spec.sleep_idle and isinstance(driver, UgvDriver)]
        self.bodies = SceneBodies(self.client, self.drivers, self.lifts, sim.scene, sim.log,
                                  clock=lambda: self.t, sleepers=sleepers)
        self.stepper = Stepper(self, sim.env, sim.log, spec, self.active, self.bodies,
                               self.local, self.execute)
        self.bodies.add_scene(sim.target)
        self.perception = Perception(self, sim)
        self.env.process(self.stepper.run())

    # -- the parts' state, as the physics pieces (Engine) and the tests read it ------------
    @property
    def t(self) -> float:
        """Physics time: whole control periods."""
        return self.stepper.t

    @property
    def movers(self) -> list[tuple[Mover, int]]:
        """The scripted movers and their bodies."""
        return self.bodies.movers

    @property
    def movers_time(self) -> float:
        """The time the movers were last put at."""
        return self.bodies.movers_time

    @property
    def target_body(self) -> int:
        """The target's body."""
        return self.bodies.target_body

    def target_now(self, now: float) -> tuple[int, FloatArray, FloatArray]:
        """The target's body, centre and size now (a patrolling one is put there first)."""
        return self.bodies.target_now(now)

    def may_ask(self, rid: str) -> bool:
        """May a robot be asked to make way now (not while it found no room lately)?"""
        return self.stepper.may_ask(rid)

    # -- services for the physics pieces ---------------------------------------------------
    def _bodies_near(self, rid: str) -> Callable[[FloatArray], list[int]]:
        """For a walker: the bodies of the other robots (UAVs, UGVs) within 1.5 m of a point,
        and the lifts'."""
        others = [d for other, d in self.drivers.items()
                  if other != rid and not isinstance(d, PlacedDriver)]

        def near(point: FloatArray) -> list[int]:
            x, y = float(point[0]), float(point[1])
            found = [d.body for d, (ox, oy, _) in ((d, d.position().tolist()) for d in others)
                     if abs(ox - x) < 1.5 and abs(oy - y) < 1.5]
            return found + [lift.body for lift in self.lifts
                            if lift.contains(point, 1.0)]

        return near

    def _column_busy(self, lift: Lift, rider: str) -> bool:
        """Is another robot in the lift's column (on any floor: the lift waits for it)?"""
        return any(rid != rider and lift.contains(driver.position(), 0.35)
                   for rid, driver in self.drivers.items())

    def clearance(self, points: FloatArray) -> FloatArray:
        """Distance to the nearest wall or slab (the navigator's map)."""
        return np.asarray(self._navigator.map.clearance(points))

    def fits(self, rid: str, points: FloatArray) -> np.ndarray:
        """Where (at its pose height) the robot's body is clear of walls and furniture."""
        return self._navigator.fits(self.robots[rid], points)

    def stands(self, rid: str, points: FloatArray) -> np.ndarray:
        """Where the robot can stand and set off from (a Husky's rectangle fits there)."""
        return self._navigator.stands(self.robots[rid], points)

    # -- the co-simulation contract ------------------------------------------------------
    def execute(self, robot: Robot, motion: Motion) -> simpy.Event:
        self.halt(robot)
        if KIND_DEFAULTS[robot.kind].flies:
            motion = self._clear_of_movers(robot, motion)
        motion.t0 = self.env.now
        self.drivers[robot.id].start(motion, self.env.now)
        return self._activate(robot, CAP_FACTOR * motion.duration + CAP_SLACK)

    def _clear_of_movers(self, robot: Robot, motion: Motion) -> Motion:
        """A UAV about to move that a walking avatar has reached while it waited (it was not
        simulated then) has risen over the avatar's head, as it would have, had it been:
        its motion starts up there."""
        here = self.drivers[robot.id].position()
        soon = self.env.now + np.linspace(0.0, RISE_AHEAD, 5)
        for mover, _ in self.movers:
            centres = mover.positions_at(soon)
            half = np.asarray(mover.size) / 2 + np.array([0.35, 0.35, 0.1])
            if np.all(np.abs(here - centres) <= half, axis=1).any():
                centre = centres[0]
                up = np.array([here[0], here[1], centre[2] + mover.size[2] / 2 + 0.35])
                if not self.fits(robot.id, up[None, :]).all():
                    continue
                self.client.call("resetBasePositionAndOrientation", self.drivers[robot.id].body,
                                 up.tolist(), [0.0, 0.0, 0.0, 1.0])
                self.log.emit("make_way", robot.id, for_robot=mover.id, to=up)
                points = np.vstack([up, motion.points[1:]]) if len(motion.points) > 1 else \
                    up[None, :]
                return Motion(points, motion.speed, accel=motion.accel,
                              turn_rate=motion.turn_rate, heading=motion.heading)
        return motion

    def face(self, robot: Robot, heading: float) -> simpy.Event:
        """Turn on the spot to ``heading``: the UGV turns its body; others look at once."""
        self.halt(robot)
        robot.heading = heading
        if not self.drivers[robot.id].turn_to(heading):
            return self.env.timeout(0.0, value=MotionOutcome(True, "arrived"))
        return self._activate(robot, TURN_CAP)

    def _activate(self, robot: Robot, cap: float) -> simpy.Event:
        """Hand a started driver to the stepper; the event fires when its motion ends."""
        track = Track(self.drivers[robot.id], self.env.now, cap)
        track.sample(self.env.now)
        track.best = (track.driver.progress(), self.env.now)
        robot.begin(track, self.env.now)
        done = self.env.event()
        self.active[robot.id] = (robot, track, done)
        self.bodies.place_movers(self.env.now)
        self.perception.moving(robot, done)
        self.stepper.wake()
        return done

    def dwell(self, robot: Robot, seconds: float) -> simpy.Event:
        self.halt(robot)
        return self.env.timeout(seconds)

    def body_pose(self, robot: Robot) -> tuple[FloatArray, FloatArray]:
        """Where the robot is now, and world from body of its simulated body."""
        driver = self.drivers[robot.id]
        return driver.position(), _body_pose(self.client, driver.body)[1]

    def halt(self, robot: Robot) -> None:
        if self.active.pop(robot.id, None) is not None:
            self.drivers[robot.id].freeze()
        robot.halt(self.env.now)

    def watch(self, robot: Robot, motion: Motion, sensor: Sensor,
              done: simpy.Event) -> simpy.Event:
        """Look for the target in rendered frames while the body moves."""
        return self.perception.watch(robot, done)

    def look(self, robot: Robot, sensor: Sensor) -> Sighting | None:
        """Render what the robot's camera sees from where it waits (around, if it pans)."""
        return self.perception.look(robot)

    def recover(self, robot: Robot) -> None:
        """A faulted robot back in service: set upright where it lies, on the floor below."""
        self.halt(robot)
        here = self.drivers[robot.id].position()
        floor = self.world.on_floor(here)
        self.drivers[robot.id].recover(floor)
        robot.pose = self.drivers[robot.id].position()

    def close(self) -> None:
        self.client.close()
        self._remove_folder()

    @property
    def step_time(self) -> float:
        return self.client.step_time


if TYPE_CHECKING:  # the contracts, as mypy checks them: this fidelity, and each body's driver
    from astralis_des.physics.uav_driver import UavDriver

    _FIDELITY: Callable[[Host], CoSim] = PhysicsCoSim
    _DRIVERS: tuple[DriverClass, ...] = (HumanDriver, UavDriver, UgvDriver)
