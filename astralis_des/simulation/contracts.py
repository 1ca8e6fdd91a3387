"""What the run's own parts (the timeline of a mission, the result it builds) see of the run:
the kernel's :class:`~astralis_des.kernel.contracts.Host` and the search's book-keeping. A
``Protocol``, so that they and :class:`~astralis_des.simulation.Simulation`, which uses them,
do not import each other."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

from astralis_des.kernel.contracts import CoSim, Host

if TYPE_CHECKING:
    import simpy

    from astralis_des.assignment import Assignment
    from astralis_des.kernel.handler import TaskHandler
    from astralis_des.kernel.robot import Robot
    from astralis_des.kernel.tasks import ActionResult, Task
    from astralis_des.mission.draws import RoomState


class Run(Host, Protocol):
    """A run in progress."""

    cosim: CoSim
    rooms: dict[str, RoomState]  # what the mission drew for each room
    rounds: list[dict[str, Any]]  # the assignment rounds so far
    allocation_time: list[float]  # wall s of each round's assignment (not logged)
    searched: list[str]  # rooms searched, in order
    tried: dict[str, set[str]]  # room -> kinds whose search saw too little of it
    finished: list[tuple[Task, ActionResult]]

    @property
    def ended(self) -> bool: ...

    def handler(self, robot_id: str) -> TaskHandler: ...
    def enqueue(self, robot_id: str, action: str, room: str | None = None,
                params: dict[str, Any] | None = None, *, origin: str = "assignment",
                round: int | None = None, preempt: bool = False) -> simpy.Event: ...
    def fault(self, robot: Robot, reason: str) -> None: ...
    def recover(self, robot: Robot) -> None: ...
    def assignment_round(self, segment: str, rooms: list[str], robots: list[Robot],
                         exclude: dict[str, set[str]] | None = None) -> Assignment: ...
