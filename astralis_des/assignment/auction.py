"""``auction``: sequential single-item auction (Koenig, Tovey, Lagoudakis et al., "The power of
sequential single-item auctions for agent coordination", AAAI 2006; the task auction of
Open-RMF's dispatcher).

Every pending room of the mission is auctioned, one at a time: each agent that may take a room
bids what appending it to its queue adds (the travel from the end of its queue, then the room's
Table IV search, both estimated by :mod:`.durations`), and the lowest bid over all rooms and
agents wins; the winner appends the room, and the auction goes on with the rooms left. With
``options.bid: finish`` an agent bids its queue's finish time instead (Open-RMF's
quickest-finish evaluator), which spreads the rooms over the team. Ties go to the lower agent,
then room, index.
"""

from __future__ import annotations

import numpy as np

from astralis_des.assignment.plans import Plan, Problem
from astralis_des.assignment.strategies import register_planner


@register_planner("auction", whole_mission=True, options=("bid",))
def auction(problem: Problem) -> Plan:
    """Sequential single-item auction over every pending room of the mission: the lowest bid
    (what the room adds to a queue, or with ``bid: finish`` the queue's finish time) wins,
    room after room."""
    n_a, n_r = problem.allowed.shape
    finish = problem.options.get("bid", "marginal") == "finish"
    queues: list[list[int]] = [[] for _ in range(n_a)]
    ends = np.zeros(n_a)  # when each queue is done, from now
    here = [problem.start(i) for i in range(n_a)]
    search = problem.search_times
    left = [j for j in range(n_r) if problem.allowed[:, j].any()]
    bids_made = 0
    while left:
        bids = np.full((n_a, n_r), np.inf)
        for i in range(n_a):
            cols = [j for j in left if problem.allowed[i, j]]
            if cols:
                added = problem.travel_from(i, here[i])[cols] + search[i, cols]
                bids[i, cols] = added + (ends[i] if finish else 0.0)
                bids_made += len(cols)
        flat = int(np.argmin(bids))  # the first lowest: by agent, then room
        i, j = flat // n_r, flat % n_r
        queues[i].append(j)
        ends[i] += float(problem.travel_from(i, here[i])[j]) + float(search[i, j])
        here[i] = problem.room_points[j]
        left.remove(j)
    return Plan(queues, {"auction_rounds": sum(len(q) for q in queues), "bids": bids_made})
