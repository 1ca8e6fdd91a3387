"""Tasks are values; an action's outcome is an :class:`ActionResult`, never an exception."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any


class TaskStatus(StrEnum):
    QUEUED = "queued"
    RUNNING = "running"
    SUCCEEDED = "succeeded"
    FAILED = "failed"
    CANCELLED = "cancelled"
    PREEMPTED = "preempted"


@dataclass(frozen=True)
class Task:
    """One primitive action for one robot, e.g. ``uav1 spiral_inward A.2.1.3``."""

    id: int
    robot: str
    action: str
    room: str | None = None
    params: tuple[tuple[str, Any], ...] = ()
    origin: str = "assignment"  # assignment | timeline | api
    round: int | None = None

    def param(self, name: str, default: Any) -> Any:
        return dict(self.params).get(name, default)

    def describe(self) -> str:
        return f"{self.action} {self.room}" if self.room else self.action


@dataclass
class ActionResult:
    """How an action ended. ``coverage`` is the share of the room's floor its sensors saw."""

    status: TaskStatus
    message: str = ""
    start: float = 0.0
    end: float = 0.0
    distance: float = 0.0
    coverage: float | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status is TaskStatus.SUCCEEDED


@dataclass(frozen=True)
class Stop:
    """The cause carried by ``process.interrupt``: how the running task must end."""

    status: TaskStatus
    message: str
