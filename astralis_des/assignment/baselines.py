"""The baselines a reviewer of a multi-robot task allocation (MRTA) paper asks for, beside the
paper's naive and mixed matchings (which already are optimal assignments: the baselines change
the rules or the objective, not the solver):

- ``hard``: the matching with hard constraints instead of weights (a human never in a room of
  risk >= ``high_risk``, a UGV never in one of messiness >= ``high_messiness``), on Eq. 1's
  distance; a room no agent may take under them makes the round *infeasible*, reported. It
  separates the effect of the weights from that of the constraints they stand for.
- ``random``: a seeded random full matching (Sadcher's random bipartite baseline).
- ``auction``, ``cbba``, ``milp``: whole queues (:mod:`.auction`, :mod:`.cbba`, :mod:`.milp`).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from astralis_des.assignment import auction, cbba, milp  # noqa: F401  (they register)
from astralis_des.assignment.eq1 import Weights, eq1_costs
from astralis_des.assignment.plans import Plan, Problem
from astralis_des.assignment.strategies import EXCLUDED, register_planner
from astralis_des.kinds import KIND_DEFAULTS


def _matching(costs: np.ndarray, allowed: np.ndarray) -> list[list[int]]:
    """A minimum-cost full matching over the allowed edges, as one-room queues."""
    queues: list[list[int]] = [[] for _ in range(costs.shape[0])]
    if costs.size == 0:
        return queues
    rows, cols = linear_sum_assignment(np.where(allowed, costs, EXCLUDED))
    for i, j in zip(rows.tolist(), cols.tolist(), strict=True):
        if allowed[i, j]:
            queues[i].append(j)
    return queues


@register_planner("hard")
def hard(problem: Problem) -> Plan:
    """Eq. 1's distance under hard constraints, the weights' intent as rules: each kind is kept
    out of the rooms high in its hazard (a person: risk >= ``high_risk``; the UGV: messiness
    >= ``high_messiness``); a round they make infeasible is reported."""
    risk = np.array([r.risk for r in problem.rooms])
    mess = np.array([r.messiness for r in problem.rooms])
    kinds = [a.kind for a in problem.agents]
    forbidden = np.zeros(problem.allowed.shape, dtype=bool)
    # each kind kept out of the rooms high in its hazard (a person: risk; the UGV: messiness)
    unsafe = {"risk": risk >= problem.high_risk, "messiness": mess >= problem.high_messiness}
    for i, kind in enumerate(kinds):
        hazard = KIND_DEFAULTS[kind].hazard
        if hazard is not None:
            forbidden[i] = unsafe[hazard]
    allowed = problem.allowed & ~forbidden
    costs = eq1_costs(problem.agents, problem.rooms, Weights.zero())
    queues = _matching(costs, allowed)
    nobody = [problem.rooms[j].id for j in range(len(problem.rooms))
              if problem.allowed[:, j].any() and not allowed[:, j].any()]
    full = sum(len(q) for q in _matching(costs, problem.allowed))  # as many as it could be
    matched = sum(len(q) for q in queues)
    info: dict[str, object] = {}
    if nobody or matched < full:  # the constraints cost a room this round
        info = {"infeasible": True, "forbidden_rooms": nobody,
                "matched": matched, "without_constraints": full}
    return Plan(queues, info)


@register_planner("random")
def random(problem: Problem) -> Plan:
    """A full matching drawn at random (uniform costs from the round's generator)."""
    costs = problem.rng.random(problem.allowed.shape)
    return Plan(_matching(costs, problem.allowed))
