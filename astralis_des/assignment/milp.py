"""``milp``: a time-limited mixed-integer program over every pending room of the mission
(Sadcher's and MRTA-Benchmark's MILP baseline), solved by HiGHS through
``scipy.optimize.milp``.

The rooms go to the agents that may take them, each room to one agent, all of them searched.
An agent's work is the Table IV search of each of its rooms (:mod:`.durations`) and the leg
into each from that room's nearest pending neighbour (an estimate of a chain through nearby
rooms: the program assigns, it does not route), and for a busy agent the way from where it
stands to the nearest pending room. ``options.objective``:

- ``makespan`` (default): minimise the latest agent's finish (unrelated parallel machines,
  R||Cmax, with a binary per agent for the first leg).
- ``sum``: minimise the sum of the rooms' completion times: room ``j`` in the ``r``-th place
  from the end of agent ``i``'s queue adds ``r`` times its duration (the classic
  position-indexed program for unrelated machines).

It reports the solver's relative gap, whether it hit ``options.time_limit`` (default 1 s of
solver time) and its status; a round that hits the limit takes the best plan found, and may then
differ from one machine to another. Each queue is ordered as a chain: the agent's room nearest
to it first, then the nearest of its rooms left.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator
from typing import Any

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, linear_sum_assignment
from scipy.optimize import milp as _highs_milp
from scipy.sparse import coo_array

from astralis_des.assignment.plans import Plan, Problem
from astralis_des.assignment.strategies import register_planner


def _hops(problem: Problem) -> np.ndarray:
    """``(A, R)``: the leg into each room from its nearest other pending room."""
    n_a, n_r = problem.allowed.shape
    hop = np.zeros((n_a, n_r))
    for i in range(n_a):
        legs = problem.room_legs[i].copy()
        np.fill_diagonal(legs, np.inf)
        hop[i] = legs.min(axis=0) if n_r > 1 else 0.0
    return hop


def _makespan(problem: Problem, search: np.ndarray, first: np.ndarray,
              hop: np.ndarray) -> tuple[Any, list[tuple[int, int]]]:
    """Unrelated parallel machines, latest finish (R||Cmax) with a busy agent's first leg.

    Rooms that cost every agent the same (the same Table IV action on the same floor area, the
    same leg in, the same agents allowed: the repeated rooms of a generated building) form a
    class, and the program counts how many rooms of each class an agent takes. That is the
    same program without its symmetry (a solver would otherwise try every permutation of equal
    rooms): 4 agents x 18 rooms of building A solve about 6 times faster. Which rooms of a
    class an agent gets is then settled by the shortest first legs (:func:`_share`).
    """
    n_a, n_r = problem.allowed.shape
    cost_of = np.where(problem.allowed, search + hop, np.inf)
    classes: dict[tuple[float, ...], list[int]] = {}
    for j in range(n_r):
        classes.setdefault(tuple(cost_of[:, j].tolist()), []).append(j)
    members = list(classes.values())
    edges = [(i, c) for c, rooms in enumerate(members) for i in range(n_a)
             if problem.allowed[i, rooms[0]]]
    e = len(edges)
    n = e + n_a + 1  # rooms of a class per agent, busy per agent, T
    lead = np.array([max(0.0, float(np.min(first[i] - hop[i]))) if n_r else 0.0
                     for i in range(n_a)])  # into the nearest room, beyond its hop
    rows: list[int] = []
    cols: list[int] = []
    vals: list[float] = []
    lo: list[float] = []
    hi: list[float] = []

    def row(entries: list[tuple[int, float]], low: float, high: float) -> None:
        for col, val in entries:
            rows.append(len(lo))
            cols.append(col)
            vals.append(val)
        lo.append(low)
        hi.append(high)

    for c, rooms in enumerate(members):  # each room once, if anyone may take it
        ks = [k for k, (_, cc) in enumerate(edges) if cc == c]
        if ks:
            row([(k, 1.0) for k in ks], len(rooms), len(rooms))
    for i in range(n_a):  # work - T <= 0; busy once it has a room
        ks = [k for k, (ii, _) in enumerate(edges) if ii == i]
        row([(k, float(cost_of[i, members[edges[k][1]][0]])) for k in ks]
            + [(e + i, float(lead[i])), (n - 1, -1.0)], -np.inf, 0.0)
        for k in ks:
            row([(k, 1.0), (e + i, -float(len(members[edges[k][1]])))], -np.inf, 0.0)
    cost = np.zeros(n)
    cost[-1] = 1.0
    integrality = np.ones(n)
    integrality[-1] = 0
    upper = np.array([len(members[c]) for _, c in edges] + [1] * n_a + [np.inf], dtype=float)
    matrix = coo_array((vals, (rows, cols)), shape=(len(lo), n)).tocsr()
    result = _solve(cost, constraints=LinearConstraint(matrix, lo, hi),
                    integrality=integrality, bounds=Bounds(np.zeros(n), upper),
                    options=_options(problem))
    if result.x is None:
        return result, []
    counts = {edges[k]: round(float(result.x[k])) for k in range(e)}
    return result, [pair for c, rooms in enumerate(members)
                    for pair in _share(first, rooms, [(i, counts.get((i, c), 0))
                                                      for i in range(n_a)])]


def _share(first: np.ndarray, rooms: list[int],
           takes: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Rooms of one class to the agents that take ``count`` of them, the sum of the first legs
    least (the program is indifferent: the rooms cost the same)."""
    slots = [i for i, count in takes for _ in range(count)]
    if not slots:
        return []
    picked, chosen = linear_sum_assignment(first[np.ix_(slots, rooms)])
    return sorted((slots[s], rooms[r]) for s, r in zip(picked, chosen, strict=True))


def _sum(problem: Problem, search: np.ndarray,
         hop: np.ndarray) -> tuple[Any, list[tuple[int, int]]]:
    n_a, n_r = problem.allowed.shape
    slots = [(i, j, r) for i in range(n_a) for j in range(n_r) for r in range(1, n_r + 1)
             if problem.allowed[i, j]]
    n = len(slots)
    cost = np.array([r * (search[i, j] + hop[i, j]) for i, j, r in slots])
    rows, lo, hi = [], [], []
    for j in range(n_r):
        ks = [k for k, s in enumerate(slots) if s[1] == j]
        if ks:
            r = np.zeros(n)
            r[ks] = 1.0
            rows.append(r)
            lo.append(1.0)
            hi.append(1.0)
    for i in range(n_a):
        for place in range(1, n_r + 1):
            ks = [k for k, s in enumerate(slots) if s[0] == i and s[2] == place]
            if ks:
                r = np.zeros(n)
                r[ks] = 1.0
                rows.append(r)
                lo.append(-np.inf)
                hi.append(1.0)
    result = _solve(cost, constraints=LinearConstraint(np.array(rows), lo, hi),
                  integrality=np.ones(n), bounds=Bounds(np.zeros(n), np.ones(n)),
                  options=_options(problem))
    chosen = [] if result.x is None else [slots[k] for k in range(n) if result.x[k] > 0.5]
    return result, [(i, j) for i, j, _ in chosen]


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Stdout and stderr of the process closed for the solve: HiGHS 1.x prints
    ``transformNewIntegerFeasibleSolution tmpSolver.run();`` from C++ whatever its output
    settings (ERGO-Code/HiGHS#2783, fixed after the version SciPy 1.17 bundles)."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    try:
        saved = [os.dup(1), os.dup(2)]
    except OSError:  # no such descriptors (an embedded interpreter): nothing to hide
        yield
        return
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, null):
            os.close(fd)


def _solve(*args: Any, **kwargs: Any) -> Any:
    with _quiet():
        return _highs_milp(*args, **kwargs)


def _options(problem: Problem) -> dict[str, Any]:
    return {"time_limit": float(problem.options.get("time_limit", 1.0)),
            "mip_rel_gap": float(problem.options.get("mip_gap", 0.01)), "disp": False}


@register_planner("milp", whole_mission=True, options=("objective", "time_limit", "mip_gap"))
def milp_plan(problem: Problem) -> Plan:
    """A mixed-integer program over every pending room of the mission (HiGHS): the makespan or
    the sum of completion times, to ``mip_gap`` or ``time_limit``."""
    objective = str(problem.options.get("objective", "makespan"))
    search, first, hop = problem.search_times, problem.first_legs, _hops(problem)
    if objective == "sum":
        result, pairs = _sum(problem, search, hop)
    else:
        result, pairs = _makespan(problem, search, first, hop)
    queues = [_chain(problem, i, [j for ii, j in pairs if ii == i])
              for i in range(problem.allowed.shape[0])]
    gap = getattr(result, "mip_gap", None)
    info = {"objective": objective, "status": int(result.status),
            "hit_limit": int(result.status) == 1,
            "gap": None if gap is None or not np.isfinite(gap) else round(float(gap), 6),
            "value": None if result.fun is None else round(float(result.fun), 6)}
    return Plan(queues, info)


def _chain(problem: Problem, i: int, rooms: list[int]) -> list[int]:
    """Agent ``i``'s rooms in order: the one nearest to where it stands, then the nearest of
    those left."""
    if not rooms:
        return []
    first = problem.first_legs[i]
    order = [min(rooms, key=lambda j: (first[j], j))]
    left = [j for j in rooms if j != order[0]]
    while left:
        legs = problem.room_legs[i][order[-1]]
        nxt = min(left, key=lambda j: (legs[j], j))
        order.append(nxt)
        left.remove(nxt)
    return order
