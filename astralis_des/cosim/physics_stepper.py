"""The physics co-simulation's stepper: one process that advances the physics and checks the
moving robots.

It advances the physics in whole control periods (``substeps`` physics steps of ``dt`` each)
while at least one controller is active, in macro-steps up to the next pending event
(``env.peek()``), stopping early when a controller finishes; then it yields ``env.timeout``
for the time stepped and fires the completion events. With nothing moving it waits on an
event, so idle time costs nothing. Physics time is quantised to the control period: an event
between two ticks sees the state of the last one.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Generator
from typing import TYPE_CHECKING, Any

import numpy as np
import simpy

from astralis_des.kernel.contracts import MotionOutcome
from astralis_des.kernel.robot import Motion, Robot
from astralis_des.physics.local import RATE as LOCAL_RATE
from astralis_des.physics.local import LocalLayer, Requests
from astralis_des.physics.make_way import aside

if TYPE_CHECKING:
    from astralis_des.cosim.physics_bodies import SceneBodies
    from astralis_des.kernel.events import EventLog
    from astralis_des.mission.spec import PhysicsSpec
    from astralis_des.physics.engine import Engine
    from astralis_des.physics.track import Track

CONTACT_CHECKS_PER_S = 30
PROGRESS = 0.1  # m of its path a moving robot must make good within stuck_timeout


class Stepper:
    """Physics time and the process that advances it: each tick drives the active robots,
    checks that they are sound, keeps the movers near them moving, looks for contacts and
    asks the local layer; robots it asks to make way are moved between macro-steps."""

    def __init__(self, engine: Engine, env: simpy.Environment, log: EventLog, spec: PhysicsSpec,
                 active: dict[str, tuple[Robot, Track, simpy.Event]], bodies: SceneBodies,
                 local: LocalLayer, execute: Callable[[Robot, Motion], simpy.Event]) -> None:
        """``active`` is the co-simulation's robots in motion (it adds them, the stepper
        finishes them); ``execute`` starts a motion (a robot making way)."""
        self.engine, self.env, self.log, self.spec = engine, env, log, spec
        self.active, self.bodies, self.local, self.execute = active, bodies, local, execute
        self.t = 0.0  # physics time: whole control periods
        self._wake: simpy.Event = env.event()
        self._next_log = 0.0
        self._asked: Requests = {}  # robots asked to make way in this macro-step
        self._no_room: dict[str, float] = {}  # robots that found no spot to make way, until
        self._ticks = 0
        site = engine.world.site
        self._site = (float(site[0]) + 5.0, float(site[1]) + 5.0)  # beyond this: left the world

    def wake(self) -> None:
        """A robot was handed over: step again if idle."""
        if not self._wake.triggered:
            self._wake.succeed()

    def run(self) -> Generator[simpy.Event, Any, None]:
        """The stepper's process."""
        env, period = self.env, self.engine.period
        while True:
            if not self.active:
                self._wake = env.event()
                yield self._wake
                self.t = math.ceil(env.now / period - 1e-9) * period
                if self.t > env.now:
                    yield env.timeout(self.t - env.now)
                continue
            ticks = math.floor((env.peek() - self.t) / period + 1e-9)
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
        period, client, bodies = self.engine.period, self.engine.client, self.bodies
        check_every = max(1, round(1.0 / (CONTACT_CHECKS_PER_S * period)))
        local_every = max(1, round(1.0 / (LOCAL_RATE * period)))
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
            if bodies.movers and check:
                bodies.move_movers(self.local.near, self.t + period)
            client.step()
            self.t += period
            self._ticks += 1
            if check:
                bodies.contacts(self.active, self.t)
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
        x, y, z = track.driver.position().tolist()  # plain floats: numpy costs more here
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            return MotionOutcome(False, "the physics state became NaN")
        if not (-5.0 <= x <= self._site[0] and -5.0 <= y <= self._site[1] and -1.0 <= z <= 200.0):
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
        return self._no_room.get(rid, -1.0) <= self.t and not self.engine.robots[rid].faulted

    def _make_way(self) -> None:
        """Robots standing idle in another's way move to the nearest free spot off its path
        (asked by the local layer during the last macro-step)."""
        robots, drivers = self.engine.robots, self.engine.drivers
        requests, self._asked = self._asked, {}
        for rid, (asker, path) in sorted(requests.items()):
            robot = robots[rid]
            if rid in self.active or robot.faulted or self._no_room.get(rid, -1.0) > self.t:
                continue
            here = drivers[rid].position()
            spot = aside(self.engine, robot, here, path, robots[asker].kind)
            if spot is None:
                self._no_room[rid] = self.t + 2.0  # nowhere to go: ask again later
                continue
            self.log.emit("make_way", rid, at=self.t, for_robot=asker, to=spot)
            motion = Motion(np.array([here, spot]), robot.speed, accel=robot.accel,
                            turn_rate=robot.turn_rate, heading=robot.heading)
            self.execute(robot, motion)

    def _finish(self, rid: str, outcome: MotionOutcome) -> None:
        """A motion ended: a faulted robot falls where it is, the body stops, and the
        motion's event fires with ``outcome``."""
        robot, track, done = self.active.pop(rid)
        driver = self.engine.drivers[rid]
        if outcome.fault:  # it comes down where it is and lies there, a still body
            driver.fall(self.engine.world.on_floor(driver.position()))
        track.sample(self.env.now)
        driver.freeze()
        robot.halt(self.env.now)
        done.succeed(outcome)
