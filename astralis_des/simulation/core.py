"""A :class:`Simulation` runs one mission: one SimPy environment. Nothing of a run is global;
what a process keeps between runs is what depends on a world alone, cached on the world
(:mod:`astralis_des.memo` lists it), and never changes what a run computes."""

from __future__ import annotations

import itertools
import logging
import time
from collections.abc import Callable, Generator
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import simpy

from astralis_des.actions import ACTIONS
from astralis_des.actions.common import MotionFailed
from astralis_des.cosim import load_fidelity
from astralis_des.exits import deferred_interrupts
from astralis_des.kernel.contracts import PluginSensor
from astralis_des.kernel.events import EventLog
from astralis_des.kernel.handler import TaskHandler
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import ActionResult, Stop, Task, TaskStatus
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.mission.changes import Changes
from astralis_des.mission.draws import draw_rooms, draw_target
from astralis_des.mission.loader import Mission
from astralis_des.mission.spec import MemberSpec
from astralis_des.navsensors import BodySamples, PoseSensors, motion_poses
from astralis_des.planning.navigator import Navigator
from astralis_des.plugins import SENSORS, check_params
from astralis_des.sensing import GeometricSensor, Sighting
from astralis_des.simulation.assignment_rounds import AssignmentRounds
from astralis_des.simulation.fork import ForkPoint, prepare
from astralis_des.simulation.outputs import OUTPUTS
from astralis_des.simulation.result import RunResult, build_result
from astralis_des.simulation.timeline import scheduled, search
from astralis_des.streams import stream
from astralis_des.view import View
from astralis_des.world.flight import flight_height
from astralis_des.world.scene import Scene

log = logging.getLogger(__name__)
Progress = Callable[[float, float], None]
PLAIN = frozenset({str, int, float, bool})  # parameter values whose check is kept
WIND_DOWN = frozenset({"found", "not_found", "team_lost"})  # ends after which the UAVs land
LANDING_LIMIT = 60.0  # s of simulated time the wind-down may take
# The process that searches the mission's rooms (the timeline's rounds by default; an
# environment's agents decide them instead): it returns why the search stopped.
Searcher = Callable[["Simulation"], Generator[simpy.Event, Any, str]]


class Simulation(AssignmentRounds):
    """One mission run. ``run()`` returns a :class:`RunResult`; with ``out_dir`` it also
    writes ``events.jsonl``, ``summary.json`` and ``recording.rrd`` there."""

    def __init__(self, mission: Mission, *, out_dir: str | Path | None = None,
                 progress: Progress | None = None, view: bool = False,
                 searcher: Searcher | None = None) -> None:
        spec = mission.spec
        self.view = view  # also stream the recording to a spawned Rerun viewer
        self.searcher = searcher or search  # the process that decides the rounds
        self._held: list[tuple[str, str, str]] = []
        self._end: simpy.Event | None = None
        self.mission = mission
        self.world = mission.world
        self.env = simpy.Environment()
        self.log = EventLog(self.env)
        self.rooms = draw_rooms(mission)
        self.scene = Scene(self.world, {r: s.messiness for r, s in self.rooms.items()},
                           spec.seed, mission.clutter_catalogue(), clutter=spec.scene.clutter,
                           movers=spec.scene.movers, mover_speed=spec.scene.mover_speed,
                           furnish_outdoors=spec.scene.furnish_outdoors,
                           on_skipped=self._not_placed)
        self.target = draw_target(mission, self.scene)
        self.sensor = GeometricSensor(self.scene, self.target,
                                      stream(spec.seed, "sensing"))
        self.found = self.env.event()
        self.rounds: list[dict[str, Any]] = []
        self.allocation_time: list[float] = []  # wall s of each round's assignment
        self.searched: list[str] = []
        self.tried: dict[str, set[str]] = {}  # room -> kinds whose search saw too little of it
        self.finished: list[tuple[Task, ActionResult]] = []
        self.out_dir = Path(out_dir) if out_dir is not None else None
        self._progress = progress
        self._ids = itertools.count(1)
        self._started: dict[str, tuple[int, float]] = {}  # robot -> running task, its start
        self._handlers: dict[str, TaskHandler] = {}
        self._timeline: simpy.Process | None = None
        self._limit: simpy.Event | None = None
        self._sinks: Any = None
        self._wall0 = time.perf_counter()
        self.flight_height = flight_height(self.world, mission.clutter_catalogue())
        self.robots = {m.id: self._make_robot(m) for m in spec.team}
        self.navigator = Navigator(self.world, self.scene, spec)
        self.cosim = load_fidelity(spec.fidelity)(self)
        self.sensors: dict[str, dict[str, PluginSensor]] = {  # robot -> name -> plug-in
            m.id: {name: SENSORS.get(name)(self, self.robots[m.id], params)
                   for name, params in m.sensor_set.plugins.items()}
            for m in spec.team if m.sensor_set.plugins}
        # GNSS, barometers, magnetometers: read from the pose, in either fidelity (a
        # simulated body's is sampled at their reading times)
        self.pose_sensors = PoseSensors.of(self, motion_poses)
        self._bodies: BodySamples | None = None
        body_pose = self.cosim.body_pose
        if body_pose is not None and self.pose_sensors.sensors:
            self._bodies = BodySamples(self.env, body_pose)
            self.pose_sensors.poses = self._bodies.poses

    # -- set-up ----------------------------------------------------------------------------
    def _not_placed(self, room: str, kind: str, reason: str) -> None:
        """An item a room had no place for: an event (held until the run starts)."""
        if self._end is None:
            self._held.append((room, kind, reason))
        else:
            self.log.emit("clutter_skipped", room=room, item=kind, reason=reason)

    def _make_robot(self, member: MemberSpec) -> Robot:
        d = KIND_DEFAULTS[member.kind]
        # a UAV starts landed, and flies at the world's height
        height = member.height or (self.flight_height if d.flies else d.height)
        if isinstance(member.start, str):
            start = np.array(self.world.rooms[member.start].center)
        else:
            start = np.array(member.start, dtype=float)
        start = start + np.array([0.0, 0.0, d.rest if d.rest is not None else height])
        robot = Robot(member.id, member.kind, member.speed or d.speed, view_of(member),
                      height, start, accel=d.accel, turn_rate=d.turn_rate, airborne=not d.flies)
        robot.trail_t.append(0.0)
        robot.trail_p.append(start.copy())

        def run(task: Task) -> Generator[simpy.Event, Any, ActionResult]:
            return self._run_action(robot, task)

        def changed(task: Task, result: ActionResult | None) -> None:
            self._task_changed(robot, task, result)

        self._handlers[member.id] = TaskHandler(self.env, run, changed)
        robot.handler = self._handlers[member.id]
        return robot

    def handler(self, robot_id: str) -> TaskHandler:
        return self._handlers[robot_id]

    # -- tasks -----------------------------------------------------------------------------
    def enqueue(self, robot_id: str, action: str, room: str | None = None,
                params: dict[str, Any] | None = None, *, origin: str = "assignment",
                round: int | None = None, preempt: bool = False) -> simpy.Event:
        """Queue a task for a robot; the returned event succeeds with its ActionResult. A
        parameter the action does not take, or a bad value, is a ``ValueError`` (one line)."""
        task = Task(next(self._ids), robot_id, action, room,
                    checked_params(self.robots[robot_id].kind, action, params or {}), origin,
                    round)
        self.log.emit("task_queued", robot_id, task=task.id, action=action, room=room,
                      origin=origin)
        handler = self._handlers[robot_id]
        return handler.preempt(task) if preempt else handler.submit(task)

    def _run_action(self, robot: Robot, task: Task) -> Generator[simpy.Event, Any, ActionResult]:
        start, travelled = self.env.now, robot.distance
        try:
            action = ACTIONS.get((robot.kind, task.action))
            outcome = yield from action.run(self, robot, task)
        except MotionFailed as failure:
            self.cosim.halt(robot)
            outcome = ActionResult(TaskStatus.FAILED, str(failure),
                                   distance=robot.distance - travelled)
            if failure.fault:
                self.fault(robot, str(failure))
        except simpy.Interrupt as stop:
            cause = stop.cause if isinstance(stop.cause, Stop) else Stop(
                TaskStatus.CANCELLED, str(stop.cause))
            self.cosim.halt(robot)
            outcome = ActionResult(cause.status, cause.message,
                                   distance=robot.distance - travelled)
        outcome.start, outcome.end = start, self.env.now
        return outcome

    def _task_changed(self, robot: Robot, task: Task, result: ActionResult | None) -> None:
        if result is None:
            self._started[robot.id] = (task.id, self.env.now)
            self.log.emit("task_started", robot.id, task=task.id, action=task.action,
                          room=task.room)
            return
        running = self._started.get(robot.id)
        if running is not None and running[0] == task.id:
            robot.busy_time += self.env.now - self._started.pop(robot.id)[1]
        self.finished.append((task, result))
        payload: dict[str, Any] = {"task": task.id, "action": task.action, "room": task.room,
                                   "status": result.status.value, "message": result.message,
                                   "distance": result.distance}
        if result.coverage is not None:
            payload["coverage"] = result.coverage
        self.log.emit("task_finished", robot.id, **payload)

    def fault(self, robot: Robot, reason: str) -> None:
        """The robot is down (it crashed, or a fault was injected): a ``fault`` event; its
        running task fails, its queued ones are cancelled, and it takes no more rooms."""
        if robot.faulted:
            return
        robot.faulted = True
        self.log.emit("fault", robot.id, reason=reason)
        self.handler(robot.id).fail(f"robot fault: {reason}")

    def recover(self, robot: Robot) -> None:
        """A faulted robot is back in service (in physics, set upright where it lies)."""
        robot.faulted = False
        self.cosim.recover(robot)
        self.log.emit("recover", robot.id)

    # -- detection -------------------------------------------------------------------------
    def report_detection(self, robot: Robot, sighting: Sighting) -> None:
        if self.found.triggered:
            return
        extra = {"pixels": sighting.pixels} if sighting.pixels is not None else {}
        self.log.emit("detection", robot.id, sensor="camera", target_room=self.target.room,
                      estimate=sighting.estimate, error=sighting.error,
                      target_position=sighting.target_position,
                      robot_position=sighting.robot_position, distance=sighting.distance,
                      **extra, avatar=self.target.avatar)
        self.found.succeed(robot.id)

    # -- running ---------------------------------------------------------------------------
    def run(self) -> RunResult:
        """Run until the target is found, the rooms run out or the time limit; then write."""
        try:  # an interrupt while starting still ends the outputs with mission_end
            self.start()
            self.advance()
        finally:
            result = self.finish()
        return result

    def fork(self, at: str | ForkPoint, changes: Changes) -> RunResult:
        """Run as ``run()`` does up to the fork point ``at`` (``round:N``, ``event:N`` or
        ``time:T``), then make ``changes`` (``{KEY: value}`` or ``"KEY=VALUE"`` strings, as
        ``astralis run --set``) and run on (docs/howto/fork.md). A point the run never
        reaches raises :class:`~astralis_des.simulation.fork.ForkNotReached`, the run in it."""
        return prepare(self.mission, at, changes).run(self, Simulation)

    def start(self) -> None:
        """Open the outputs and start the timeline; ``advance`` then moves time on."""
        if self._end is not None:
            return
        with deferred_interrupts():  # the outputs open whole, and say the mission started
            self._open()

    def _open(self) -> None:
        spec = self.mission.spec
        self._wall0 = time.perf_counter()
        self._sinks = OUTPUTS.get("files")(self, self.out_dir)
        if self._progress is not None:
            progress = self._progress
            self.log.sinks.append(lambda rec: progress(rec["t"], spec.time_limit))
        self.log.emit("mission_start", mission=spec.name, seed=spec.seed,
                      fidelity=spec.fidelity, target_room=self.target.room,
                      team=[m.id for m in spec.team])
        ends = [self.found]
        if spec.assignment.auto:  # else the rounds come from commands (the API's assign)
            self._timeline = self.env.process(self.searcher(self))
            ends.append(self._timeline)
        for event in spec.timeline:
            self.env.process(scheduled(self, event))
        if self._bodies is not None:
            self._bodies.start(self.pose_sensors)
        for mine in self.sensors.values():
            for sensor in mine.values():
                self.env.process(sensor.run())
        self._limit = self.env.timeout(spec.time_limit)
        self._end = simpy.AnyOf(self.env, [*ends, self._limit])
        for held in self._held:
            self._not_placed(*held)
        # The end stops env.run() itself: wrapping it in another condition would not do, as a
        # SimPy condition that fires strips the checks of the conditions nested in it.
        self._end.callbacks.append(simpy.core.StopSimulation.callback)

    def advance(self, until: float | None = None) -> bool:
        """Run to simulated time ``until`` (or the end); true once the mission has ended."""
        self.start()
        assert self._end is not None
        if not self._end.triggered and (until is None or until > self.env.now):
            self.env.run(until=until)
        return self._end.triggered

    @property
    def started(self) -> bool:
        """Whether the outputs are open and the mission under way (``start``)."""
        return self._end is not None

    @property
    def ended(self) -> bool:
        """Whether the mission has ended (found, searched out, team lost or out of time)."""
        return self._end is not None and self._end.triggered

    @property
    def recorded(self) -> bool:
        """Whether the outputs keep what the sensors saw: a recording or an MCAP file in
        ``out_dir`` (the physics cameras' kept frames are rendered only for them)."""
        cfg = self.mission.spec.outputs
        return self.out_dir is not None and (cfg.recording or cfg.mcap)

    @property
    def outputs_time(self) -> float:
        """Wall seconds spent writing this run's outputs (event log, summary, recording)."""
        return self._sinks.seconds if self._sinks is not None else 0.0

    def finish(self) -> RunResult:
        """End the run where it is: halt the robots, close the outputs, return the result.
        A signal meanwhile does not cut the outputs short: it ends the landings of the wind-
        down at once, and is raised (``KeyboardInterrupt``) once the outputs are in place."""
        if self.found.triggered:
            outcome = "found"
        elif self._timeline is not None and self._timeline.triggered:
            outcome = str(self._timeline.value)
        elif self._limit is not None and self._limit.processed:  # a Timeout is "triggered"
            outcome = "time_limit"                                  # as soon as it exists
        else:
            outcome = "interrupted"
        cut: KeyboardInterrupt | None = None
        if outcome in WIND_DOWN:
            try:
                self._wind_down()
            except KeyboardInterrupt as signal:
                cut = signal
        with deferred_interrupts():
            result = self._close(outcome)
        if cut is not None:
            raise cut
        return result

    def _close(self, outcome: str) -> RunResult:
        for robot in self.robots.values():
            self.cosim.halt(robot)
            if robot.id in self._started:  # still at work when the mission ended
                robot.busy_time += self.env.now - self._started.pop(robot.id)[1]
        self.pose_sensors.update(float(self.env.now))  # while the bodies are there to read
        self.cosim.close()
        self.log.emit("mission_end", outcome=outcome)
        result = build_result(self, outcome, time.perf_counter() - self._wall0)
        if self._sinks is not None:
            self._sinks.close(result)
        log.info("%s: %s at t=%.1f s", self.mission.spec.name, outcome, self.env.now)
        return result

    def _wind_down(self) -> None:
        """The mission is over: each robot's tasks end (``cancelled``, "mission ended") and
        the UAVs in the air land where they are (``land`` tasks), within ``LANDING_LIMIT``."""
        waits = []
        for robot in self.robots.values():
            handler = self.handler(robot.id)
            waits += [handler.done_event(t.id) for t in handler.cancel(reason="mission ended")]
        waits += [self.enqueue(r.id, "land", origin="mission") for r in self.robots.values()
                  if r.airborne and not r.faulted and KIND_DEFAULTS[r.kind].flies]
        if waits:
            over = simpy.AnyOf(self.env, [simpy.AllOf(self.env, waits),
                                          self.env.timeout(LANDING_LIMIT)])
            while not over.triggered:  # an earlier advance(until)'s stop may still be due
                self.env.run(until=over)


def checked_params(kind: str, action: str, params: dict[str, Any]
                   ) -> tuple[tuple[str, Any], ...]:
    """``check_params``'s answer as a task holds it (sorted pairs). Plain values (the rounds'
    door, a hold's duration) are checked once per process and version of the actions'
    registry: the answer depends on nothing else."""
    if not params:
        return ()
    if all(type(v) in PLAIN for v in params.values()):
        return _checked(kind, action, tuple((k, type(v), v.hex() if type(v) is float else v)
                                            for k, v in params.items()), ACTIONS.version)
    return tuple(sorted(check_params(kind, action, params).items()))


@lru_cache(maxsize=1024)
def _checked(kind: str, action: str, key: tuple[tuple[str, type, Any], ...], version: int
             ) -> tuple[tuple[str, Any], ...]:
    params = {k: float.fromhex(v) if t is float else v for k, t, v in key}
    return tuple(sorted(check_params(kind, action, params).items()))


def view_of(member: MemberSpec) -> View | None:
    """The field of view of a member's camera: the mission's values, else its kind's."""
    camera = member.sensor_set.camera
    if camera is None:
        return None
    set_here = {k: v for k, v in (("range", camera.range), ("fov_deg", camera.fov_deg),
                                  ("pitch_deg", camera.pitch_deg)) if v is not None}
    return View.of_kind(member.kind, (camera.width, camera.height), camera.min_pixels,
                        position_noise=camera.position_noise, **set_here)
