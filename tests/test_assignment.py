"""Tests for :mod:`astralis_des.assignment`: Eq. 1 costs, the matching, the strategies."""

from __future__ import annotations

from fractions import Fraction as F

import numpy as np
import pytest
from numpy.testing import assert_allclose

from astralis_des.assignment import Agent, RoomInfo, Weights, assign, eq1_costs, match
from astralis_des.registry import UnknownEntry

# The paper's default weights (the mission schema's): W1 on risk, W2 on messiness, per kind.
PAPER = Weights({"human": 10.0, "uav": 5.0, "ugv": 0.0},
                {"human": 10.0, "uav": 0.0, "ugv": 5.0})

# Three rooms on the floor plane, z = 0:
#   R0 = (0, 0)   risk 0.2  messiness 0.6
#   R1 = (6, 0)   risk 0.8  messiness 0.0
#   R2 = (0, 8)   risk 0.5  messiness 0.4
ROOMS = [RoomInfo("R0", (0.0, 0.0, 0.0), 0.2, 0.6),
         RoomInfo("R1", (6.0, 0.0, 0.0), 0.8, 0.0),
         RoomInfo("R2", (0.0, 8.0, 0.0), 0.5, 0.4)]
# Four agents, kinds [human, uav, uav, ugv]:
AGENTS = [Agent("op", "human", (0.0, 4.0, 0.0)),
          Agent("uav1", "uav", (0.0, 0.0, 0.0)),
          Agent("uav2", "uav", (3.0, 4.0, 0.0)),
          Agent("ugv", "ugv", (6.0, 8.0, 0.0))]
# Distances (l2 for a UAV, Manhattan for the human and the UGV), then / the agent's mean:
#   op   (0,4) Manhattan: R0 0+4=4,   R1 6+4=10, R2 0+4=4   mean 6     -> 2/3, 5/3, 2/3
#   uav1 (0,0) l2:        R0 0,       R1 6,      R2 8       mean 14/3  -> 0, 9/7, 12/7
#   uav2 (3,4) l2:        R0 5,       R1 5,      R2 5       mean 5     -> 1, 1, 1
#   ugv  (6,8) Manhattan: R0 6+8=14,  R1 0+8=8,  R2 6+0=6   mean 28/3  -> 3/2, 6/7, 9/14
#   (the UGV's l2 distances would be 10, 8, 6: Manhattan matters)
# Weighted terms risk*W1 + messiness*W2:
#   human: 10r + 10m = R0 2+6=8, R1 8+0=8, R2 5+4=9
#   uav:    5r       = R0 1,     R1 4,     R2 5/2
#   ugv:         5m  = R0 3,     R1 0,     R2 2
NORM = [[F(2, 3), F(5, 3), F(2, 3)],
        [F(0), F(9, 7), F(12, 7)],
        [F(1), F(1), F(1)],
        [F(3, 2), F(6, 7), F(9, 14)]]
TERMS = {"human": [8, 8, 9], "uav": [1, 4, F(5, 2)], "ugv": [3, 0, 2]}
#   E = NORM + TERMS:
#   op   [26/3, 29/3, 29/3]
#   uav1 [1,    37/7, 59/14]
#   uav2 [2,    5,    7/2]
#   ugv  [9/2,  6/7,  37/14]
EXPECTED = [[F(26, 3), F(29, 3), F(29, 3)],
            [F(1), F(37, 7), F(59, 14)],
            [F(2), F(5), F(7, 2)],
            [F(9, 2), F(6, 7), F(37, 14)]]
# Best matching: uav1-R0 (1) + ugv-R1 (6/7) + uav2-R2 (7/2) = 5 5/14 ~ 5.357; the next best,
# uav2-R0 + ugv-R1 + uav1-R2 = 2 + 6/7 + 59/14 ~ 7.07. The human is left out.
BEST = [(1, 0), (2, 2), (3, 1)]
# Naive (distance only, NORM): uav1-R0 (0) + ugv-R1 (6/7) + op-R2 (2/3) = 1 11/21 ~ 1.524;
# next best uav1-R0 + uav2-R1 + ugv-R2 = 0 + 1 + 9/14 ~ 1.643. The human goes to R2.
NAIVE_BEST = [(0, 2), (1, 0), (3, 1)]


def as_float(matrix: list[list[F]]) -> np.ndarray:
    return np.array([[float(v) for v in row] for row in matrix])


def total(cost: np.ndarray, pairs: list[tuple[int, int]]) -> float:
    return float(sum(cost[i, j] for i, j in pairs))


def test_eq1_by_hand() -> None:
    """Eq. 1 on the 4 x 3 example equals the matrix worked out by hand above."""
    costs = eq1_costs(AGENTS, ROOMS, PAPER)
    assert costs.shape == (4, 3)
    assert_allclose(costs, as_float(EXPECTED), rtol=0, atol=1e-12)
    by_kind = [[n + TERMS[a.kind][j] for j, n in enumerate(row)]
               for a, row in zip(AGENTS, NORM, strict=True)]
    assert by_kind == EXPECTED  # the comment's two tables add up to the third


def test_eq1_without_weights_is_the_normalised_distance() -> None:
    """With zero weights each row is the agent's distances over their mean (row mean 1)."""
    costs = eq1_costs(AGENTS, ROOMS, Weights.zero())
    assert_allclose(costs, as_float(NORM), rtol=0, atol=1e-12)
    assert_allclose(costs.mean(axis=1), np.ones(4), rtol=0, atol=1e-12)


def test_eq1_agent_on_all_rooms_costs_zero_distance() -> None:
    """An agent whose distances are all zero gets a normalised distance of 0, not NaN."""
    rooms = [RoomInfo("a", (1.0, 1.0, 0.0), 0.0, 0.0), RoomInfo("b", (1.0, 1.0, 0.0), 1.0, 0.0)]
    costs = eq1_costs([Agent("u", "uav", (1.0, 1.0, 0.0))], rooms, PAPER)
    assert_allclose(costs, [[0.0, 5.0]])


@pytest.mark.parametrize("solver", ["scipy", "networkx"])
def test_match_example(solver: str) -> None:
    """Both solvers find the hand-worked best matching of the example."""
    costs = eq1_costs(AGENTS, ROOMS, PAPER)
    pairs = match(costs, solver)
    assert pairs == BEST
    assert total(costs, pairs) == pytest.approx(float(F(1) + F(6, 7) + F(7, 2)))


@pytest.mark.parametrize("solver", ["scipy", "networkx"])
def test_match_naive_example(solver: str) -> None:
    """Both solvers find the hand-worked distance-only matching, zero-cost entry included."""
    costs = eq1_costs(AGENTS, ROOMS, Weights.zero())
    assert match(costs, solver) == NAIVE_BEST


def test_solvers_agree_on_random_matrices() -> None:
    """scipy and networkx agree in total cost on 200 random rectangular matrices."""
    gen = np.random.default_rng(20240601)
    shapes = [(4, 3), (3, 4), (2, 5), (5, 5), (5, 2), (1, 4), (4, 1), (6, 3)]
    for k in range(200):
        shape = shapes[k % len(shapes)]
        if k % 2:  # small integers: ties and zeros
            cost = gen.integers(0, 4, size=shape).astype(float)
        else:
            cost = gen.uniform(0.0, 10.0, size=shape)
        a, b = match(cost, "scipy"), match(cost, "networkx")
        assert total(cost, a) == pytest.approx(total(cost, b), abs=1e-9), (k, cost)
        for pairs in (a, b):
            rows, cols = zip(*pairs, strict=True)
            assert len(pairs) == min(shape)
            assert len(set(rows)) == len(rows) and len(set(cols)) == len(cols)
            assert list(rows) == sorted(rows)


@pytest.mark.parametrize("shape", [(4, 3), (3, 4), (2, 5), (5, 2), (5, 5), (1, 1)])
def test_matching_size(shape: tuple[int, int]) -> None:
    """|M| = min(|A|, |R|) for both solvers."""
    cost = np.random.default_rng(1).uniform(size=shape)
    assert len(match(cost, "scipy")) == min(shape)
    assert len(match(cost, "networkx")) == min(shape)


def test_match_empty() -> None:
    """No agents or no rooms: an empty matching."""
    assert match(np.zeros((0, 3))) == []
    assert match(np.zeros((3, 0)), "networkx") == []


def test_assign_mixed_example() -> None:
    """``assign`` (mixed) gives the hand-worked pairs, their costs, actions and the left-out."""
    plan = assign(AGENTS, ROOMS, PAPER, strategy="mixed")
    assert [(p.agent, p.room) for p in plan.pairs] == [("uav1", "R0"), ("uav2", "R2"),
                                                        ("ugv", "R1")]
    assert [p.cost for p in plan.pairs] == pytest.approx([1.0, 3.5, 6 / 7])
    # Table IV: R0 (0.2, 0.6) low risk, high mess; R2 (0.5, 0.4) high risk (0.5 is high);
    # R1 (0.8, 0.0) high risk.
    assert [p.action for p in plan.pairs] == ["sweep_horizontal", "spiral_inward",
                                              "observe_corridor"]
    assert plan.unassigned == ("op",)
    assert plan.agents == ("op", "uav1", "uav2", "ugv")
    assert plan.rooms == ("R0", "R1", "R2")
    assert plan.total_cost == pytest.approx(1 + 3.5 + 6 / 7)
    assert plan.room_of("ugv") == "R1"
    assert plan.room_of("op") is None


@pytest.mark.parametrize("solver", ["scipy", "networkx"])
def test_naive_ignores_risk_and_messiness(solver: str) -> None:
    """``naive`` gives the same costs and matching as ``mixed`` with zero weights."""
    naive = assign(AGENTS, ROOMS, PAPER, strategy="naive", solver=solver)
    zero = assign(AGENTS, ROOMS, Weights.zero(), strategy="mixed", solver=solver)
    assert_allclose(naive.costs, zero.costs)
    assert naive.pairs == zero.pairs
    assert [(p.agent, p.room) for p in naive.pairs] == [("op", "R2"), ("uav1", "R0"),
                                                         ("ugv", "R1")]
    # And changing the rooms' risk and messiness changes nothing for it.
    calm = [RoomInfo(r.id, r.position, 0.0, 0.0) for r in ROOMS]
    assert [(p.agent, p.room) for p in assign(AGENTS, calm, PAPER, strategy="naive",
                                              solver=solver).pairs] == \
        [(p.agent, p.room) for p in naive.pairs]


def test_mixed_keeps_the_human_out_of_a_high_risk_room() -> None:
    """A high-risk room next to the human: naive sends the human in, mixed does not."""
    # R2 now has risk 0.9, messiness 0.1. Naive ignores that: op-R2 as in NAIVE_BEST.
    # Mixed, R2 column: op 2/3 + 9 + 1 = 10 2/3, uav1 12/7 + 4.5, uav2 1 + 4.5, ugv 9/14 + 0.5;
    # best: uav1-R0 (1) + uav2-R1 (5) + ugv-R2 (8/7) = 7 1/7, vs 7 5/14 with uav2-R2.
    rooms = [ROOMS[0], ROOMS[1], RoomInfo("R2", ROOMS[2].position, 0.9, 0.1)]
    naive = assign(AGENTS, rooms, PAPER, strategy="naive")
    mixed = assign(AGENTS, rooms, PAPER, strategy="mixed")
    assert naive.room_of("op") == "R2"
    assert next(p.action for p in naive.pairs if p.agent == "op") == "inspect"
    assert mixed.room_of("op") is None
    assert mixed.unassigned == ("op",)
    assert [(p.agent, p.room, p.action) for p in mixed.pairs] == [
        ("uav1", "R0", "sweep_horizontal"), ("uav2", "R1", "spiral_inward"),
        ("ugv", "R2", "observe_corridor")]
    assert mixed.total_cost == pytest.approx(1 + 5 + 8 / 7)


def test_greedy_takes_the_nearest_pair_first() -> None:
    """Greedy nearest pairs the closest agent and room first, even when that costs more in
    total than the optimal matching on the same travel times."""
    # a1 at x=0, a2 at x=3; R0 at x=1, R1 at x=-3. Travel times (l2 / 1.5 m/s):
    #   a1: R0 1/1.5, R1 3/1.5;  a2: R0 2/1.5, R1 6/1.5.
    # Greedy: a1-R0 (the cheapest), then a2-R1: 7/1.5. Optimal: a1-R1 + a2-R0: 5/1.5.
    agents = [Agent("a1", "uav", (0.0, 0.0, 0.0)), Agent("a2", "uav", (3.0, 0.0, 0.0))]
    rooms = [RoomInfo("R0", (1.0, 0.0, 0.0), 0.9, 0.9), RoomInfo("R1", (-3.0, 0.0, 0.0), 0, 0)]
    plan = assign(agents, rooms, PAPER, strategy="greedy")
    assert [(p.agent, p.room) for p in plan.pairs] == [("a1", "R0"), ("a2", "R1")]
    assert plan.total_cost == pytest.approx(7 / 1.5)
    assert_allclose(plan.costs, [[1 / 1.5, 3 / 1.5], [2 / 1.5, 6 / 1.5]])
    assert match(plan.costs, "scipy") == [(0, 1), (1, 0)]  # optimal: 5 / 1.5


def test_unknown_strategy_lists_valid_names() -> None:
    """An unknown strategy raises UnknownEntry listing the valid ones."""
    with pytest.raises(UnknownEntry) as info:
        assign(AGENTS, ROOMS, PAPER, strategy="bazaar")
    assert str(info.value) == ("unknown assignment strategy 'bazaar'; "
                               "valid: auction, cbba, greedy, hard, milp, mixed, naive, random")


def test_misspelt_strategy_suggests_the_close_name() -> None:
    """A misspelt strategy raises UnknownEntry with a 'did you mean' hint."""
    with pytest.raises(UnknownEntry, match=r"did you mean 'mixed'\?"):
        assign(AGENTS, ROOMS, PAPER, strategy="mixd")


def test_unknown_solver_lists_valid_names() -> None:
    """An unknown solver raises UnknownEntry listing the valid ones."""
    with pytest.raises(UnknownEntry) as info:
        assign(AGENTS, ROOMS, PAPER, solver="hungarian")
    assert str(info.value) == ("unknown matching solver 'hungarian'; "
                               "valid: greedy, networkx, scipy")
    with pytest.raises(UnknownEntry, match="valid: greedy, networkx, scipy"):
        match(np.ones((2, 2)), "hungarian")


def test_misspelt_solver_suggests_the_close_name() -> None:
    """A misspelt solver raises UnknownEntry with a 'did you mean' hint."""
    with pytest.raises(UnknownEntry, match=r"did you mean 'networkx'\?"):
        match(np.ones((2, 2)), "netwrkx")


def test_unknown_entry_is_a_lookup_error() -> None:
    """UnknownEntry can be caught as a LookupError."""
    with pytest.raises(LookupError):
        assign(AGENTS, ROOMS, PAPER, strategy="nope")


def test_a_rounds_room_is_given_as_it_is_now() -> None:
    """A round's room carries the room's risk and messiness as they are: kept while they
    stay, made anew after a room change sets either."""
    from pathlib import Path

    from astralis_des import Simulation, load_mission

    mission = load_mission(Path(__file__).parents[1] / "missions" / "urban_search.yaml")
    sim = Simulation(mission)
    rid = mission.searched_rooms()[0]
    first = sim.room_info(rid)
    assert sim.room_info(rid) is first
    assert (first.risk, first.messiness) == (sim.rooms[rid].risk, sim.rooms[rid].messiness)
    assert first.position == sim.world.rooms[rid].center
    sim.rooms[rid].messiness = 0.875  # what a room_change event does
    changed = sim.room_info(rid)
    assert (changed.risk, changed.messiness, changed.area) == (first.risk, 0.875, first.area)
    _, infos, _, _ = sim.round_inputs([rid], [])
    assert infos == [changed]
