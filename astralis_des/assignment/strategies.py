"""Assignment strategies by registry: ``mixed`` (Eq. 1 with W1, W2), ``naive`` (Eq. 1's
distance alone) and ``greedy`` (nearest by travel time, one pair at a time) give each agent at
most one room a round; the baselines (:mod:`astralis_des.assignment.baselines`) plan whole
queues (``auction``, ``cbba``, ``milp``) or match under other rules (``hard``, ``random``)."""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from astralis_des.assignment.eq1 import Agent, RoomInfo, Weights, distances, eq1_costs
from astralis_des.assignment.matching import match
from astralis_des.assignment.plans import Plan, Planner, Problem, queue_times
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
    pairs: tuple[Pair, ...]  # each agent's in the order it searches them
    unassigned: tuple[str, ...]
    info: dict[str, Any] = field(default_factory=dict)  # a planner's report on the round

    @property
    def total_cost(self) -> float:
        return float(sum(p.cost for p in self.pairs))

    def room_of(self, agent: str) -> str | None:
        return next((p.room for p in self.pairs if p.agent == agent), None)


EXCLUDED = 1e9  # the cost a solver sees for an edge that does not exist
Costs = Callable[[Sequence[Agent], Sequence[RoomInfo], Weights], NDArray[np.float64]]


@dataclass(frozen=True)
class Strategy:
    """A cost matrix and the matcher that pairs on it (None: the mission's solver), or a
    planner of whole queues; ``whole_mission``: it is given every pending room of the mission
    at once, not a segment's; ``options``: the keys of the mission's ``assignment.options``
    it reads (``docs/missions.md`` lists them per strategy)."""

    costs: Costs | None = None
    matcher: str | None = None
    planner: Planner | None = None
    whole_mission: bool = False
    options: tuple[str, ...] = ()

    @property
    def doc(self) -> str:
        """The first paragraph of its function's docstring, on one line."""
        run = self.costs if self.costs is not None else self.planner
        return " ".join((inspect.getdoc(run) or "").split("\n\n")[0].split())

    def __call__(self, agents: Sequence[Agent], rooms: Sequence[RoomInfo],
                 weights: Weights) -> NDArray[np.float64]:
        if self.costs is None:  # a planner's matrix, for the record: Eq. 1's distance
            return eq1_costs(agents, rooms, Weights.zero())
        return self.costs(agents, rooms, weights)


STRATEGIES: Registry[str, Strategy] = _STRATEGIES  # held in the foundations, by name


def register_strategy(name: str, matcher: str | None = None) -> Callable[[Costs], Costs]:
    def add(costs: Costs) -> Costs:
        STRATEGIES.register(name)(Strategy(costs, matcher))
        return costs

    return add


def register_planner(name: str, *, whole_mission: bool = False,
                     options: tuple[str, ...] = ()) -> Callable[[Planner], Planner]:
    def add(planner: Planner) -> Planner:
        STRATEGIES.register(name)(Strategy(planner=planner, whole_mission=whole_mission,
                                           options=options))
        return planner

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
           high_messiness: float = 0.5, reachable: NDArray[np.bool_] | None = None,
           rng: np.random.Generator | None = None,
           options: Mapping[str, Any] | None = None) -> Assignment:
    """Match agents to rooms (or plan their queues) and pick each action by Table IV.

    ``reachable[i, j]`` false excludes the edge: its cost is infinite, the matching avoids it,
    and an agent left with only such edges stays unassigned (the room stays pending). ``rng``
    (the round's generator) and ``options`` (the mission's ``assignment.options``) are for
    the strategies that draw or take parameters.
    """
    chosen = STRATEGIES.get(strategy)
    if chosen.planner is not None:
        allowed = np.ones((len(agents), len(rooms)), dtype=bool) if reachable is None \
            else np.asarray(reachable, dtype=bool)
        problem = Problem(agents, rooms, weights, allowed,
                          rng if rng is not None else np.random.default_rng(0), high_risk,
                          high_messiness, dict(options or {}))
        return _planned(problem, chosen.planner(problem), chosen(agents, rooms, weights))
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


def _planned(problem: Problem, plan: Plan, costs: NDArray[np.float64]) -> Assignment:
    """A planner's queues as pairs, each costing its estimated finish time from the start."""
    agents, rooms = problem.agents, problem.rooms
    pairs = []
    for i, queue in enumerate(plan.queues):
        for j, t in zip(queue, queue_times(problem, i, queue), strict=True):
            pairs.append(Pair(agents[i].id, rooms[j].id, round(t, 6), problem.action(i, j)))
    busy = {p.agent for p in pairs}
    return Assignment(tuple(a.id for a in agents), tuple(r.id for r in rooms),
                      np.where(problem.allowed, costs, np.inf), tuple(pairs),
                      tuple(a.id for a in agents if a.id not in busy), plan.info)
