"""The kernel's contracts: what plugs into a run, and what a run offers to what plugs in.

The plug-ins (actions, co-simulations, sensors, sinks) are written against these
``Protocol``s, never against :class:`~astralis_des.simulation.Simulation` itself, so the
imports flow one way: the composition root (``astralis_des.simulation``) imports the
plug-ins and wires them; the plug-ins import only the kernel and what lies below it.

- :class:`MotionOutcome`: how a motion ended (what a co-simulation's events carry).
- :class:`Host`: what a run offers a co-simulation and its sensors (time, the event log,
  the mission, the world and its scene, the robots, the routes, the target, and whether
  its outputs record what the sensors saw).
- :class:`CoSim`: a fidelity; it turns each robot's motions and looks into simulated time.
  What only some fidelities can do is declared, not probed: ``body_pose`` and
  ``perception`` are ``None`` where the fidelity simulates no body and no sensor of its own.
- :class:`Perceived`: what a fidelity's own sensors kept (the physics fidelity's
  ``Perception``), for the sinks and the result.
- :class:`Sensor`: the geometric sensing a co-simulation consults (kinematic detection and
  coverage).
- :class:`Context`: what an action gets (``action(ctx, robot, task)``).
- :class:`Output`: a sink; it sees every event, then the run's result.
- :class:`PluginSensor`: a sensor a mission adds by name (``astralis_des.plugins.SENSORS``).
"""

from __future__ import annotations

from collections.abc import Callable, Generator, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

if TYPE_CHECKING:
    import simpy

    from astralis_des.detection import Sighting
    from astralis_des.kernel.events import EventLog
    from astralis_des.kernel.perceived import ImuTrace, KeptCloud, KeptFrame, KeptScan
    from astralis_des.kernel.robot import Motion, Robot
    from astralis_des.mission.loader import Mission
    from astralis_des.planning.navigator import Navigator
    from astralis_des.world.geometry import FloatArray
    from astralis_des.world.model import Room, World
    from astralis_des.world.scene import Scene, Target


@dataclass(frozen=True)
class MotionOutcome:
    """How a motion ended: arrived, or failed with a reason (stuck, left the world, ...).
    ``fault``: the robot cannot go on (it crashed, fell): it leaves the mission."""

    ok: bool
    reason: str
    fault: bool = False


class Host(Protocol):
    """What a run offers a co-simulation and the sensors it starts."""

    @property
    def env(self) -> simpy.Environment: ...
    @property
    def log(self) -> EventLog: ...
    @property
    def mission(self) -> Mission: ...
    @property
    def world(self) -> World: ...
    @property
    def scene(self) -> Scene: ...
    @property
    def navigator(self) -> Navigator: ...
    @property
    def robots(self) -> dict[str, Robot]: ...
    @property
    def target(self) -> Target: ...
    @property
    def recorded(self) -> bool:
        """Whether the run's outputs keep what the sensors saw (a recording or an MCAP
        file): without, the frames kept only for them need not be rendered."""
        ...


class Sensor(Protocol):
    """Geometric sensing from the scene: first sightings and the share of a room seen."""

    @property
    def scene(self) -> Scene: ...

    def first_sighting(self, robot: Robot, motion: Motion) -> Sighting | None: ...
    def sighting_from(self, robot: Robot, position: FloatArray,
                      now: float) -> Sighting | None: ...
    def coverage(self, robot: Robot, points: FloatArray, room: Room,
                 headings: FloatArray | None = None) -> float: ...


BodyPose = Callable[["Robot"], tuple["FloatArray", "FloatArray"]]
"""Where a robot's simulated body is now, and its attitude (world from body)."""


class SensorCounts(Protocol):
    """Wall seconds and calls per sensor (the benchmark's)."""

    @property
    def seconds(self) -> Mapping[str, float]: ...
    @property
    def calls(self) -> Mapping[str, int]: ...


class Perceived(Protocol):
    """What a fidelity's own sensors kept during a run: camera frames, lidar scans and
    clouds, IMU traces per robot (the records of :mod:`astralis_des.kernel.perceived`), and
    what they cost."""

    @property
    def clock(self) -> SensorCounts: ...
    @property
    def frames(self) -> Sequence[KeptFrame]: ...
    @property
    def scans(self) -> Sequence[KeptScan]: ...
    @property
    def clouds(self) -> Sequence[KeptCloud]: ...
    @property
    def imu_traces(self) -> Mapping[str, ImuTrace]: ...


@runtime_checkable
class CoSim(Protocol):
    """A fidelity: each call returns an event that fires when the motion (or look, or wait)
    is over, with a ``MotionOutcome``. ``body_pose`` and ``perception`` are capabilities:
    ``None`` where the fidelity has no simulated body or no sensors of its own."""

    @property
    def body_pose(self) -> BodyPose | None: ...
    @property
    def perception(self) -> Perceived | None: ...

    def execute(self, robot: Robot, motion: Motion) -> simpy.Event: ...
    def watch(self, robot: Robot, motion: Motion, sensor: Sensor,
              done: simpy.Event) -> simpy.Event: ...
    def dwell(self, robot: Robot, seconds: float) -> simpy.Event: ...
    def face(self, robot: Robot, heading: float) -> simpy.Event: ...
    def halt(self, robot: Robot) -> None: ...
    def look(self, robot: Robot, sensor: Sensor) -> Sighting | None: ...
    def recover(self, robot: Robot) -> None: ...
    def close(self) -> None: ...


class Context(Protocol):
    """What an action gets from the run it is part of."""

    @property
    def env(self) -> simpy.Environment: ...
    @property
    def world(self) -> World: ...
    @property
    def cosim(self) -> CoSim: ...
    @property
    def sensor(self) -> Sensor: ...
    @property
    def navigator(self) -> Navigator: ...
    @property
    def log(self) -> EventLog: ...
    @property
    def robots(self) -> dict[str, Robot]: ...

    def report_detection(self, robot: Robot, sighting: Sighting) -> None: ...


class PluginSensor(Protocol):
    """A sensor added by name: ``SENSORS.get(name)(host, robot, params)`` builds it when the
    run is set up; the run starts ``run()`` as a process when the mission starts (it reads
    at its own rate, from the robot's pose or the fidelity's state, and keeps or emits what
    it reads)."""

    def run(self) -> Generator[simpy.Event, Any, None]: ...
