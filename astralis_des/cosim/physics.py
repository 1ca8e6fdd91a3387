"""Physics fidelity: a PyBullet co-simulation behind the kinematic contract.

One stepper process advances the physics in whole control periods (``substeps`` physics steps
of ``dt`` each) while at least one controller is active, in macro-steps up to the next pending
event (``env.peek()``), stopping early when a controller finishes; then it yields
``env.timeout`` for the time stepped and fires the completion events. With nothing moving it
waits on an event, so idle time costs nothing. Physics time is quantised to the control
period: an event between two ticks sees the state of the last one.
"""

from __future__ import annotations

import math
import shutil
import tempfile
from collections.abc import Callable, Generator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import simpy

from astralis_des.detection import Sighting
from astralis_des.kernel.contracts import CoSim, Host, MotionOutcome, Sensor
from astralis_des.kernel.robot import Motion, Robot
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.drivers import DRIVERS, Driver, DriverClass, HumanDriver, PlacedDriver
from astralis_des.physics.hexacopter import write_urdf
from astralis_des.physics.lift import Lift, lifts_of
from astralis_des.physics.local import RATE as LOCAL_RATE
from astralis_des.physics.local import LocalLayer, Requests
from astralis_des.physics.make_way import aside
from astralis_des.physics.perception import Perception
from astralis_des.physics.sensors import _body_pose
from astralis_des.physics.track import Track
from astralis_des.physics.ugv_driver import UgvDriver
from astralis_des.plugins import COSIMS
from astralis_des.world.clutter import Clutter
from astralis_des.world.geometry import FloatArray
from astralis_des.world.scene import Mover

CONTACT_CHECKS_PER_S = 30
PROGRESS = 0.1  # m of its path a moving robot must make good within stuck_timeout
SUPPORT = 0.7  # a contact normal steeper than this holds a ground robot up: not a collision
FLOORS = ("wall", "ground", "lift")  # what holds a ground robot up (slabs are static boxes)
CAP_FACTOR, CAP_SLACK = 2.0, 30.0  # a motion planned to take T s fails after 2 T + 30 s
TURN_CAP = 30.0  # s: a turn on the spot that takes longer has failed
RISE_AHEAD = 1.0  # s: a waiting UAV that a walking avatar reaches this soon has risen over it


@COSIMS.register("physics")
class PhysicsCoSim:
    def __init__(self, sim: Host) -> None:
        spec = sim.mission.spec.physics
        self.env, self.log, self.spec = sim.env, sim.log, spec
        self.world = sim.world
        self.period = 1.0 / spec.control_rate
        self.client = PhysicsClient(sim.world, spec.dt, spec.rate // spec.control_rate,
                                    spec.solver_iterations)
        self._folder = Path(tempfile.mkdtemp(prefix="astralis-"))
        urdf = write_urdf(spec.uav, self._folder)
        self.drivers: dict[str, Driver] = {
            rid: DRIVERS.get(robot.kind)(self.client, robot, spec, urdf)
            for rid, robot in sim.robots.items()}
        self.names = {d.body: rid for rid, d in self.drivers.items()}
        self.names.update(dict.fromkeys(self.client.static, "wall"))
        self.names[self.client.ground] = "ground"
        self.lifts = lifts_of(sim.world, self.client)
        self.names.update({lift.body: "lift" for lift in self.lifts})
        for rid, driver in self.drivers.items():
            if isinstance(driver, UgvDriver):
                driver.lifts = self.lifts
                driver.column_busy = self._column_busy
            if isinstance(driver, PlacedDriver):
                driver.bodies_near = self._bodies_near(rid)
                driver.robot_of = {d.body: other for other, d in self.drivers.items()}
        self._scene = sim.scene
        self.robots = sim.robots
        self._navigator = sim.navigator
        self.local = LocalLayer(self, list(sim.robots))
        self.t = 0.0  # physics time: whole control periods
        self._add_scene(sim)
        self.perception = Perception(self, sim)
        self.site = sim.world.site
        self.active: dict[str, tuple[Robot, Track, simpy.Event]] = {}
        self.touching: set[tuple[str, str]] = set()
        self._wake: simpy.Event = self.env.event()
        self._next_log = 0.0
        self._asked: Requests = {}  # robots asked to make way in this macro-step
        self._no_room: dict[str, float] = {}  # robots that found no spot to make way, until
        self._ticks = 0
        self.env.process(self._stepper())

    def _add_scene(self, sim: Host) -> None:
        """The target and the movers now; each room's furniture (one static body) and its
        patrolling avatars when the room is furnished, before any robot goes in."""
        scene = sim.scene
        self.movers: list[tuple[Mover, int]] = []
        self.movers_time = 0.0  # the time the movers were last put at
        self._add_movers([*scene.movers, *scene.avatar_movers()])
        for room_id in scene.furnished_rooms():
            self._furnish(room_id, scene.clutter(room_id), movers=False)
        scene.listeners.append(self._furnish)
        self.target = target = sim.target
        self.target_size = np.asarray(target.size, dtype=float)
        if target.mover is None:
            self.target_body = self.client.add_box(target.start, self.target_size)
            self.names[self.target_body] = "target"
        else:
            self.target_body = next(b for m, b in self.movers if m is target.mover)

    def target_now(self, now: float) -> tuple[int, FloatArray, FloatArray]:
        """The target's body, centre and size now (a patrolling one is put there first)."""
        if self.target.mover is None:
            return self.target_body, np.asarray(self.target.start, dtype=float), self.target_size
        centre = self.target.mover.position_at(now)
        self.client.call("resetBasePositionAndOrientation", self.target_body, centre.tolist(),
                         [0.0, 0.0, 0.0, 1.0])
        return self.target_body, centre, self.target_size

    def _furnish(self, room_id: str, clutter: Clutter, movers: bool = True) -> None:
        still = self._scene.still_boxes([room_id])
        if len(still):
            bodies = self.client.add_boxes(still[:, 0], still[:, 1])
            self.names.update(dict.fromkeys(bodies, "furniture"))
        if movers:
            self._add_movers(self._scene.avatar_movers([room_id]))

    def _add_movers(self, movers: list[Mover]) -> None:
        for mover in movers:
            body = self.client.add_box(mover.position_at(self.t), mover.size)
            self.movers.append((mover, body))
            self.names[body] = mover.kind

    def _bodies_near(self, rid: str) -> Callable[[FloatArray], list[int]]:
        """For a walker: the bodies of the other robots (UAVs, UGVs) within 1.5 m of a point,
        and the lifts'."""
        others = [d for other, d in self.drivers.items()
                  if other != rid and not isinstance(d, PlacedDriver)]

        def near(point: FloatArray) -> list[int]:
            found = [d.body for d in others
                     if abs(float(d.position()[0]) - float(point[0])) < 1.5
                     and abs(float(d.position()[1]) - float(point[1])) < 1.5]
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

    def _move_movers(self) -> None:
        """Put the movers near a moving robot where they are at the end of the coming tick.
        Done at the contact checks' rate (30 Hz): a walker then jumps about 3 cm at a time;
        one far from every moving robot touches nothing and jumps when it comes near."""
        then = self.t + self.period
        self.movers_time = then
        self._put_movers([self.movers[index] for index in self.local.near], then)

    def _place_movers(self) -> None:
        """Every mover where it is now, as a robot sets off: a body not moved while no robot
        was near it stays where it was last simulated, and a robot setting off there would
        meet it (a UAV waiting where a patrolling avatar had stopped being moved was tipped
        over by it)."""
        self._put_movers(self.movers, self.env.now)

    def _put_movers(self, movers: list[tuple[Mover, int]], t: float) -> None:
        """Each mover's body where its script has it at ``t``."""
        for mover, body in movers:
            self.client.call("resetBasePositionAndOrientation", body,
                             mover.position_at(t).tolist(), [0.0, 0.0, 0.0, 1.0])

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
        self._place_movers()
        self.perception.moving(robot, done)
        if not self._wake.triggered:
            self._wake.succeed()
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
        shutil.rmtree(self._folder, ignore_errors=True)

    @property
    def step_time(self) -> float:
        return self.client.step_time

    # -- the stepper -----------------------------------------------------------------------
    def _stepper(self) -> Generator[simpy.Event, Any, None]:
        env = self.env
        while True:
            if not self.active:
                self._wake = env.event()
                yield self._wake
                self.t = math.ceil(env.now / self.period - 1e-9) * self.period
                if self.t > env.now:
                    yield env.timeout(self.t - env.now)
                continue
            ticks = math.floor((env.peek() - self.t) / self.period + 1e-9)
            if ticks < 1:  # an event falls before the next tick: let it see this state
                yield env.timeout(max(env.peek() - env.now, 0.0))
                continue
            finished = self._advance(ticks)
            yield env.timeout(max(self.t - env.now, 0.0))
            for rid, outcome in finished:
                self._finish(rid, outcome)
            self._make_way()

    def _advance(self, ticks: int) -> list[tuple[str, MotionOutcome]]:
        """Step up to ``ticks`` control periods; stop at the first that ends a motion."""
        check_every = max(1, round(1.0 / (CONTACT_CHECKS_PER_S * self.period)))
        local_every = max(1, round(1.0 / (LOCAL_RATE * self.period)))
        for _ in range(ticks):
            check = self._ticks % check_every == 0
            make_way = False
            if self._ticks % local_every == 0:
                asked = self.local.update(self.t)
                for rid, request in asked.items():  # the first to ask in the macro-step
                    self._asked.setdefault(rid, request)
                make_way = bool(self._asked)  # end the macro-step after this tick
            finished = [(rid, out) for rid, (robot, track, _) in self.active.items()
                        if (out := self._tick(rid, track, check)) is not None]
            if finished:
                return finished
            if self.movers and check:
                self._move_movers()
            self.client.step()
            self.t += self.period
            self._ticks += 1
            if check:
                self._contacts()
            if self.t >= self._next_log:
                self._next_log = self.t + 1.0 / self.spec.log_rate
                for _, track, _ in self.active.values():
                    track.sample(self.t)
            if make_way:
                return []
        return []

    def _tick(self, rid: str, track: Track, check: bool) -> MotionOutcome | None:
        """Drive one robot for a tick; every few ticks also check that it is sound."""
        status = track.driver.tick(self.t)
        if status == "arrived":
            return MotionOutcome(True, "arrived")
        if not check:
            return None
        here = track.driver.position()
        if not np.all(np.isfinite(here)):
            return MotionOutcome(False, "the physics state became NaN")
        if not (-5.0 <= here[0] <= self.site[0] + 5.0 and -5.0 <= here[1] <= self.site[1] + 5.0
                and -1.0 <= here[2] <= 200.0):
            return MotionOutcome(False, "left the world")
        crash = track.driver.crashed()
        if crash is not None:
            return MotionOutcome(False, crash, fault=True)
        progress = track.driver.progress()
        if progress > track.best[0] + PROGRESS:
            track.best = (progress, self.t)
        elif self.t - track.best[1] > self.spec.stuck_timeout:
            return MotionOutcome(False, f"stuck: no progress for {self.spec.stuck_timeout:g} s")
        if self.t - track.t0 > track.cap:
            return MotionOutcome(False, f"timed out: not there after {track.cap:.0f} s")
        return None

    def may_ask(self, rid: str) -> bool:
        """May a robot be asked to make way now (not while it found no room lately)?"""
        return self._no_room.get(rid, -1.0) <= self.t and not self.robots[rid].faulted

    def _make_way(self) -> None:
        """Robots standing idle in another's way move to the nearest free spot off its path
        (asked by the local layer during the last macro-step)."""
        requests, self._asked = self._asked, {}
        for rid, (asker, path) in sorted(requests.items()):
            robot = self.robots[rid]
            if rid in self.active or robot.faulted or self._no_room.get(rid, -1.0) > self.t:
                continue
            here = self.drivers[rid].position()
            spot = aside(self, robot, here, path, self.robots[asker].kind)
            if spot is None:
                self._no_room[rid] = self.t + 2.0  # nowhere to go: ask again later
                continue
            self.log.emit("make_way", rid, at=self.t, for_robot=asker, to=spot)
            motion = Motion(np.array([here, spot]), robot.speed, accel=robot.accel,
                            turn_rate=robot.turn_rate, heading=robot.heading)
            self.execute(robot, motion)

    def _finish(self, rid: str, outcome: MotionOutcome) -> None:
        robot, track, done = self.active.pop(rid)
        if outcome.fault:  # it comes down where it is and lies there, a still body
            self.drivers[rid].fall(self.world.on_floor(self.drivers[rid].position()))
        track.sample(self.env.now)
        self.drivers[rid].freeze()
        robot.halt(self.env.now)
        done.succeed(outcome)

    def _contacts(self) -> None:
        """A robot touching a wall, the ground (a UAV) or another robot: one event a touch."""
        now: set[tuple[str, str]] = set()
        impulses: dict[tuple[str, str], float] = {}
        for rid, (robot, _, _) in self.active.items():
            body = self.drivers[rid].body
            for c in self.client.call("getContactPoints", bodyA=body):
                other = self.names.get(c[2], "object")
                if (not KIND_DEFAULTS[robot.kind].flies or not robot.airborne) and other in FLOORS \
                        and c[7][2] > SUPPORT:
                    continue  # wheels or feet on a floor, a UAV taking off or landing
                key = (rid, other)
                now.add(key)
                impulses[key] = impulses.get(key, 0.0) + c[9] * self.client.dt
        for key in sorted(now - self.touching):
            self.log.emit("contact", key[0], at=self.t, other=key[1],
                          impulse=round(impulses[key], 4))
        self.touching = now


if TYPE_CHECKING:  # the contracts, as mypy checks them: this fidelity, and each body's driver
    from astralis_des.physics.uav_driver import UavDriver

    _FIDELITY: Callable[[Host], CoSim] = PhysicsCoSim
    _DRIVERS: tuple[DriverClass, ...] = (HumanDriver, UavDriver, UgvDriver)
