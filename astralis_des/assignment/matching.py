"""Minimum-weight full matching of a rectangular cost matrix: |M| = min(|A|, |R|)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from astralis_des.registry import Registry

Matcher = Callable[[NDArray[np.float64]], list[tuple[int, int]]]
SOLVERS: Registry[str, Matcher] = Registry("matching solver")


@SOLVERS.register("scipy")
def _scipy(cost: NDArray[np.float64]) -> list[tuple[int, int]]:
    from scipy.optimize import linear_sum_assignment

    rows, cols = linear_sum_assignment(cost)
    return sorted(zip(rows.tolist(), cols.tolist(), strict=True))


@SOLVERS.register("networkx")
def _networkx(cost: NDArray[np.float64]) -> list[tuple[int, int]]:
    import networkx as nx
    from networkx.algorithms.bipartite import minimum_weight_full_matching

    n_a, n_r = cost.shape
    graph = nx.Graph()
    agents = [("a", i) for i in range(n_a)]
    graph.add_nodes_from(agents, bipartite=0)
    graph.add_nodes_from((("r", j) for j in range(n_r)), bipartite=1)
    graph.add_weighted_edges_from(
        (("a", i), ("r", j), float(cost[i, j])) for i in range(n_a) for j in range(n_r))
    top = agents if n_a <= n_r else [("r", j) for j in range(n_r)]
    mate = minimum_weight_full_matching(graph, top_nodes=top, weight="weight")
    return sorted((int(a[1]), int(mate[a][1])) for a in agents if a in mate)


@SOLVERS.register("greedy")
def _greedy(cost: NDArray[np.float64]) -> list[tuple[int, int]]:
    """Not optimal on purpose: the cheapest remaining pair first, until a side runs out."""
    order = np.argsort(cost, axis=None, kind="stable")
    rows, cols = np.unravel_index(order, cost.shape)
    used_a: set[int] = set()
    used_r: set[int] = set()
    pairs = []
    for i, j in zip(rows.tolist(), cols.tolist(), strict=True):
        if i not in used_a and j not in used_r:
            pairs.append((i, j))
            used_a.add(i)
            used_r.add(j)
    return sorted(pairs)


def match(cost: NDArray[np.float64], solver: str = "scipy") -> list[tuple[int, int]]:
    """``(agent index, room index)`` pairs of a minimum-weight full matching."""
    if cost.size == 0:
        return []
    return SOLVERS.get(solver)(np.asarray(cost, dtype=float))
