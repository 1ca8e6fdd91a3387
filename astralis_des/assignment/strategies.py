"""Assignment strategies by registry: ``mixed`` (Eq. 1 with W1, W2), ``naive`` (Eq. 1's
distance alone) and ``greedy`` (nearest by travel time, one pair at a time)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from astralis_des.assignment.eq1 import Agent, RoomInfo, Weights, distances, eq1_costs
from astralis_des.assignment.matching import match
from astralis_des.assignment.rules import table4_action
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.plugins import STRATEGIES as _STRATEGIES
from astralis_des.registry import Registry


@dataclass(frozen=True)
class Pair:
    agent: str
    room: str
    cost: float
    action: str


@dataclass(frozen=True)
class Assignment:
    agents: tuple[str, ...]
    rooms: tuple[str, ...]
    costs: NDArray[np.float64]
    pairs: tuple[Pair, ...]
    unassigned: tuple[str, ...]

    @property
    def total_cost(self) -> float:
        return float(sum(p.cost for p in self.pairs))

    def room_of(self, agent: str) -> str | None:
        return next((p.room for p in self.pairs if p.agent == agent), None)


EXCLUDED = 1e9  # the cost a solver sees for an edge that does not exist
Costs = Callable[[Sequence[Agent], Sequence[RoomInfo], Weights], NDArray[np.float64]]


@dataclass(frozen=True)
class Strategy:
    """A cost matrix, and the matcher that pairs on it (None: the mission's solver)."""

    costs: Costs
    matcher: str | None = None

    def __call__(self, agents: Sequence[Agent], rooms: Sequence[RoomInfo],
                 weights: Weights) -> NDArray[np.float64]:
        return self.costs(agents, rooms, weights)


STRATEGIES: Registry[str, Strategy] = _STRATEGIES  # held in the foundations, by name


def register_strategy(name: str, matcher: str | None = None) -> Callable[[Costs], Costs]:
    def add(costs: Costs) -> Costs:
        STRATEGIES.register(name)(Strategy(costs, matcher))
        return costs

    return add


@register_strategy("mixed")
def mixed(agents: Sequence[Agent], rooms: Sequence[RoomInfo],
          weights: Weights) -> NDArray[np.float64]:
    """The paper's mixed heuristic: Eq. 1 with the risk and messiness weights."""
    return eq1_costs(agents, rooms, weights)


@register_strategy("naive")
def naive(agents: Sequence[Agent], rooms: Sequence[RoomInfo],
          weights: Weights) -> NDArray[np.float64]:
    """The paper's baseline: Eq. 1's normalised distance alone."""
    return eq1_costs(agents, rooms, Weights.zero())


@register_strategy("greedy", matcher="greedy")
def greedy(agents: Sequence[Agent], rooms: Sequence[RoomInfo],
           weights: Weights) -> NDArray[np.float64]:
    """Greedy nearest: the pair with the shortest travel time (Eq. 1's distance over the
    kind's cruise speed, not normalised) goes first, then the next among those left; risk
    and messiness are ignored."""
    speeds = np.array([KIND_DEFAULTS[a.kind].speed for a in agents])
    return np.asarray(distances(agents, rooms) / speeds[:, None])


def assign(agents: Sequence[Agent], rooms: Sequence[RoomInfo], weights: Weights, *,
           strategy: str = "mixed", solver: str = "scipy", high_risk: float = 0.5,
           high_messiness: float = 0.5,
           reachable: NDArray[np.bool_] | None = None) -> Assignment:
    """Match agents to rooms and pick each matched agent's action by Table IV.

    ``reachable[i, j]`` false excludes the edge: its cost is infinite, the matching avoids it,
    and an agent left with only such edges stays unassigned (the room stays pending).
    """
    chosen = STRATEGIES.get(strategy)
    costs = chosen(agents, rooms, weights)
    solver = chosen.matcher or solver
    if reachable is not None:
        costs = np.where(reachable, costs, np.inf)
    finite = np.isfinite(costs)
    # The solvers want finite costs: an excluded edge costs more than any full matching.
    solvable = np.where(finite, costs, EXCLUDED)
    pairs = tuple(
        Pair(agents[i].id, rooms[j].id, float(costs[i, j]),
             table4_action(agents[i].kind, rooms[j].risk, rooms[j].messiness, high_risk,
                           high_messiness))
        for i, j in match(solvable, solver) if finite[i, j]
    )
    matched = {p.agent for p in pairs}
    return Assignment(tuple(a.id for a in agents), tuple(r.id for r in rooms), costs, pairs,
                      tuple(a.id for a in agents if a.id not in matched))
