"""What an op (a query or a command of the API) sees of the mission it serves: the
:class:`Session` protocol (:class:`~astralis_des.api.service.Service` is one), and the
:class:`Clock` that paces it. The ops type against these, so the service, which finds the
ops in their registry, and the ops do not import each other."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from astralis_des.kernel.robot import Robot
    from astralis_des.simulation import Simulation
    from astralis_des.simulation.result import RunResult
    from astralis_des.world.model import Room


class Clock:
    """Simulated time against wall time: running at ``pace`` (1 = real time), or paused
    (time then moves only on ``step``)."""

    def __init__(self, pace: float = 1.0, running: bool = True) -> None:
        self.pace = pace
        self.running = running
        self._wall0 = time.perf_counter()
        self._sim0 = 0.0

    def anchor(self, sim_now: float) -> None:
        self._wall0, self._sim0 = time.perf_counter(), sim_now

    def target(self) -> float:
        """The simulated time it is now, by the wall clock."""
        return self._sim0 + (time.perf_counter() - self._wall0) * self.pace

    def describe(self) -> str:
        return f"running at {self.pace:g}x" if self.running else "paused"


class Session(Protocol):
    """A started mission behind the API."""

    sim: Simulation
    clock: Clock
    result: RunResult | None
    stopping: bool  # a shutdown was asked for
    teleop_goals: dict[str, tuple[int, Any]]  # robot -> (task, goal)
    addresses: dict[str, str]  # requests, stream: where the server listens

    @property
    def now(self) -> float: ...
    @property
    def ended(self) -> bool: ...
    def advance(self, until: float | None) -> bool: ...
    def end(self) -> RunResult: ...
    def robot(self, robot_id: str) -> Robot: ...
    def room(self, room_id: str) -> Room: ...
    def command_event(self, op: str, robot: str | None = None, **fields: Any) -> None: ...
