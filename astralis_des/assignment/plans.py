"""What a strategy that plans whole queues is given and gives back.

A *planner* sees every pending room at once, and gives each agent an ordered queue of rooms
(its FIFO task queue: a move to the door and the Table IV search, room after room) and what it
has to say about the round (``info``: infeasible rooms, consensus rounds and messages, a MILP's
gap); the matching strategies give at most one room an agent, as the paper's rounds do.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import NDArray

from astralis_des.assignment.durations import search_seconds, travel_seconds
from astralis_des.assignment.eq1 import Agent, RoomInfo, Weights
from astralis_des.assignment.rules import table4_action


@dataclass(frozen=True)
class Problem:
    """One round: the agents, the pending rooms, who may take which (reachable, not excluded)
    and the round's own generator (seeded from the mission's seed and the round)."""

    agents: Sequence[Agent]
    rooms: Sequence[RoomInfo]
    weights: Weights
    allowed: NDArray[np.bool_]  # (A, R)
    rng: np.random.Generator
    high_risk: float = 0.5
    high_messiness: float = 0.5
    options: Mapping[str, Any] = field(default_factory=dict)

    def action(self, i: int, j: int) -> str:
        room = self.rooms[j]
        return table4_action(self.agents[i].kind, room.risk, room.messiness, self.high_risk,
                             self.high_messiness)

    def search(self, i: int, j: int) -> float:
        """Seconds agent ``i`` takes to search room ``j`` (its Table IV action)."""
        return search_seconds(self.agents[i].kind, self.action(i, j), self.rooms[j].area)

    @cached_property
    def room_points(self) -> NDArray[np.float64]:
        return np.array([r.position for r in self.rooms], dtype=float).reshape(-1, 3)

    @cached_property
    def search_times(self) -> NDArray[np.float64]:
        """``(A, R)``: :meth:`search` of every agent and room."""
        n_a, n_r = self.allowed.shape
        return np.array([[self.search(i, j) for j in range(n_r)] for i in range(n_a)]
                        ).reshape(n_a, n_r)

    @cached_property
    def first_legs(self) -> NDArray[np.float64]:
        """``(A, R)``: seconds from each agent's start to each room."""
        n_a, n_r = self.allowed.shape
        return np.array([self.travel_from(i, self.start(i)) for i in range(n_a)]
                        ).reshape(n_a, n_r)

    @cached_property
    def room_legs(self) -> list[NDArray[np.float64]]:
        """Per agent, ``(R, R)``: seconds from each room to each room."""
        return [np.array([self.travel_from(i, p) for p in self.room_points]
                         ).reshape(len(self.rooms), len(self.rooms))
                for i in range(len(self.agents))]

    def travel_from(self, i: int, point: NDArray[np.float64]) -> NDArray[np.float64]:
        """Seconds agent ``i`` takes from ``point`` to each room."""
        return travel_seconds(self.agents[i].kind, point, self.room_points)

    def start(self, i: int) -> NDArray[np.float64]:
        return np.asarray(self.agents[i].position, dtype=float)


@dataclass
class Plan:
    """Each agent's queue of room indices, in the order it searches them, and the round's
    report (only plain JSON values: it goes into the event log)."""

    queues: list[list[int]]
    info: dict[str, Any] = field(default_factory=dict)


Planner = Callable[[Problem], Plan]


def queue_times(problem: Problem, i: int, queue: Sequence[int]) -> list[float]:
    """When agent ``i`` would finish each room of ``queue``, from its start."""
    t, here, done = 0.0, problem.start(i), []
    points = problem.room_points
    for j in queue:
        t += float(problem.travel_from(i, here)[j]) + problem.search(i, j)
        here = points[j]
        done.append(t)
    return done
