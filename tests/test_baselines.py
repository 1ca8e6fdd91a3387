"""The allocation baselines (issue 21) on small cases worked by hand, and in whole missions."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from astralis_des.assignment import Agent, RoomInfo, Weights, assign
from astralis_des.assignment.cbba import CBBA, NONE, TABLE_1, Bids
from astralis_des.assignment.plans import Problem
from astralis_des.mission.loader import load_mission
from astralis_des.simulation import Simulation

ROOT = Path(__file__).resolve().parents[1]
W = Weights.zero()


def agents(kind: str, *xs: float) -> list[Agent]:
    return [Agent(f"a{i}", kind, (x, 0.0, 0.0)) for i, x in enumerate(xs)]


def rooms(*xs: float, area: float = 0.0, risk: float = 0.0, mess: float = 0.0) -> list[RoomInfo]:
    return [RoomInfo(f"r{j}", (x, 0.0, 0.0), risk, mess, area) for j, x in enumerate(xs)]


def queues(plan: object) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for p in plan.pairs:  # type: ignore[attr-defined]
        out.setdefault(p.agent, []).append(p.room)
    return out


# -- auction ---------------------------------------------------------------------------------
def test_a_3_by_3_auction_by_hand() -> None:
    """People (Manhattan, 1.2 m/s) at x = 0, 10, 100; rooms of 10 m^2 (3.77 s to inspect) at
    x = 1, 2, 3. Marginal bids: the first person's next room always adds 0.83 + 3.77 = 4.60 s,
    less than the second person's 7 / 1.2 + 3.77 = 9.60 s, so she takes all three. Finish-time
    bids: after r0 (4.60 s) and with r1 she would finish at 9.21 s, before the second person
    could finish r2 (9.60 s): r1 is hers; r2 then ends at 13.81 s with her, 9.60 s with him."""
    team, where = agents("human", 0, 10, 100), rooms(1, 2, 3, area=10.0)
    marginal = assign(team, where, W, strategy="auction")
    assert queues(marginal) == {"a0": ["r0", "r1", "r2"]}
    assert marginal.unassigned == ("a1", "a2")
    finish = assign(team, where, W, strategy="auction", options={"bid": "finish"})
    assert queues(finish) == {"a0": ["r0", "r1"], "a1": ["r2"]}
    assert [p.cost for p in finish.pairs] == pytest.approx(
        [1 / 1.2 + 3.77, 2 * (1 / 1.2 + 3.77), 7 / 1.2 + 3.77])  # finish times from the start
    assert finish.info == {"auction_rounds": 3, "bids": 9 + 6 + 3}


# -- cbba ------------------------------------------------------------------------------------
def test_cbba_resolves_a_conflict_step_by_step() -> None:
    """UAVs at x = 0 and 3, rooms at x = 1 and 10, bundles of one, reward 0.9 a second. Both
    first bid on r0 (0.9 ** (1 / 1.5) = 0.932 against 0.9 ** (2 / 1.5) = 0.869); on hearing
    each other the first keeps it (table: sender names itself, receiver names itself: the
    higher bid stays), the second updates to the first and drops r0, then bids on r1."""
    problem = Problem(agents("uav", 0, 3), rooms(1, 10), W, np.ones((2, 2), dtype=bool),
                      np.random.default_rng(0), options={"bundle": 1, "discount": 0.9})
    run = CBBA(problem)
    run.build_bundle(0)
    run.build_bundle(1)
    a0, a1 = run.agents
    assert (a0.bundle, a1.bundle) == ([0], [0])
    assert a0.y[0] == pytest.approx(0.9 ** (1 / 1.5))
    assert a1.y[0] == pytest.approx(0.9 ** (2 / 1.5))
    run.consensus()
    assert a0.bundle == [0] and a0.z.tolist() == [0, NONE]
    assert a1.bundle == [] and a1.z.tolist() == [0, NONE]  # outbid: released
    assert a1.y[0] == pytest.approx(0.9 ** (1 / 1.5))  # it knows the winning bid now
    run.build_bundle(0)
    run.build_bundle(1)
    assert a1.bundle == [1] and a1.y[1] == pytest.approx(0.9 ** (7 / 1.5))
    run.consensus()
    assert a0.z.tolist() == a1.z.tolist() == [0, 1]  # agreed
    assert run.run()  # nothing more changes
    assert run.messages == 2 * run.iteration  # each of two agents tells the other, each time
    plan = assign(problem.agents, problem.rooms, W, strategy="cbba",
                  options={"bundle": 1, "discount": 0.9})
    assert queues(plan) == {"a0": ["r0"], "a1": ["r1"]}
    assert plan.info["converged"] is True


@pytest.mark.parametrize(("sender", "receiver", "yk", "yi", "newer", "action"), [
    ("k", "i", 0.5, 0.4, False, "update"),  # the sender's own bid is higher
    ("k", "i", 0.4, 0.5, False, "leave"),
    ("i", "k", 0.5, 0.5, False, "reset"),  # each thinks the other won: reset
    ("none", "k", 0.0, 0.5, False, "update"),  # the sender dropped it: follow
    ("m", "k", 0.5, 0.5, False, "reset"),  # stale news of m: reset
    ("m", "k", 0.5, 0.5, True, "update"),
])
def test_table_1_cells(sender: str, receiver: str, yk: float, yi: float, newer: bool,
                       action: str) -> None:
    """Cells of the decision table, agents i = 0, k = 1, m = 2."""
    who = {"i": 0, "k": 1, "m": 2, "none": NONE}
    sk, si = np.zeros(3), np.zeros(3)
    if newer:
        sk[2] = 1.0
    bids = Bids(yk, who[sender], yi, who[receiver], 1, 0, sk, si, CBBA.outbids)
    assert TABLE_1[(sender, receiver)](bids) == action


# -- milp ------------------------------------------------------------------------------------
def test_milp_finds_the_known_optimum() -> None:
    """Two UAVs and four rooms at one spot (no travel) of 40, 30, 30 and 20 m^2, an outward
    spiral each (0.432 s/m^2): the best split is 60 m^2 each, 25.92 s; the least sum of
    completion times puts 20 then 30 on one, 30 then 40 on the other: 170 m^2, 73.44 s."""
    team = agents("uav", 0, 0)
    where = [RoomInfo(f"r{j}", (0.0, 0.0, 0.0), 0.0, 0.0, a)
             for j, a in enumerate((40.0, 30.0, 30.0, 20.0))]
    plan = assign(team, where, W, strategy="milp")
    assert plan.info["value"] == pytest.approx(60 * 0.432)
    assert plan.info["gap"] <= 0.01 and not plan.info["hit_limit"]
    loads = sorted(sum(r.area for r in where if r.id in q) for q in queues(plan).values())
    assert loads == [60.0, 60.0]
    plan = assign(team, where, W, strategy="milp", options={"objective": "sum"})
    assert plan.info["value"] == pytest.approx(170 * 0.432)


# -- hard and random -------------------------------------------------------------------------
def test_hard_keeps_the_rules_and_reports_a_round_they_make_infeasible() -> None:
    team = [Agent("op", "human", (0.0, 0.0, 0.0)), Agent("husky", "ugv", (1.0, 0.0, 0.0))]
    where = [RoomInfo("risky", (1.0, 0.0, 0.0), 0.9, 0.1, 20.0),
             RoomInfo("messy", (2.0, 0.0, 0.0), 0.1, 0.9, 20.0)]
    plan = assign(team, where, W, strategy="hard")
    assert queues(plan) == {"op": ["messy"], "husky": ["risky"]}  # the rules, not distance
    assert plan.info == {}
    where.append(RoomInfo("both", (3.0, 0.0, 0.0), 0.9, 0.9, 20.0))
    plan = assign(team, where, W, strategy="hard")
    assert plan.info["infeasible"] is True
    assert plan.info["forbidden_rooms"] == ["both"]
    assert all(p.room != "both" for p in plan.pairs)


def test_random_is_a_full_matching_drawn_from_the_round_seed() -> None:
    team, where = agents("uav", 0, 5, 10), rooms(1, 6, 11, 20)

    def draw(seed: int) -> dict[str, list[str]]:
        return queues(assign(team, where, W, strategy="random",
                             rng=np.random.default_rng(seed)))

    assert draw(3) == draw(3)
    assert all(len(q) == 1 for q in draw(3).values()) and len(draw(3)) == 3
    assert len({json.dumps(draw(s), sort_keys=True) for s in range(12)}) > 3


# -- whole missions --------------------------------------------------------------------------
@pytest.mark.parametrize("strategy", ["hard", "random", "auction", "cbba", "milp"])
def test_each_baseline_runs_the_default_mission_the_same_twice(strategy: str,
                                                             tmp_path: Path) -> None:
    base = load_mission(ROOT / "missions" / "urban_search.yaml")
    mission = base.with_changes(assignment={**base.spec.assignment.model_dump(mode="json"),
                                            "strategy": strategy})
    logs = []
    for k in range(2):
        out = tmp_path / str(k)
        result = Simulation(mission, out_dir=out).run()
        logs.append((out / "events.jsonl").read_bytes())
        assert result.outcome == "found"
    assert logs[0] == logs[1]
    if strategy in ("auction", "cbba", "milp"):  # one round plans every room of building A
        first = result.rounds[0]
        assert first["segment"] == "all" and len(first["rooms"]) == 18
        assert len({p["agent"] for p in first["matching"]}) < len(first["matching"])


# -- metrics ---------------------------------------------------------------------------------
def test_gini_of_workloads() -> None:
    from astralis_des.simulation.metrics import gini

    assert gini(np.array([2.0, 2.0, 2.0, 2.0])) == 0.0
    assert gini(np.array([0.0, 0.0, 0.0, 4.0])) == pytest.approx(0.75)  # (n - 1) / n
    assert gini(np.array([1.0, 3.0])) == pytest.approx(0.25)  # mean |diff| / (2 mean)
    assert gini(np.zeros(3)) == 0.0


def test_social_metrics_of_a_robot_passing_a_person() -> None:
    """A person stands at the origin; a UAV flies along y = 1 m from x = -5 to 5 at 1 m/s:
    it comes 1.0 m close, and is within 1.2 m while |x| < 0.663 m, for 1.33 s."""
    from types import SimpleNamespace

    from astralis_des.simulation.metrics import social

    person = SimpleNamespace(kind="human", trail_t=[0.0, 10.0],
                             trail_p=[np.zeros(3), np.zeros(3)], motion=None, pose=np.zeros(3))
    uav = SimpleNamespace(kind="uav", trail_t=[0.0, 10.0],
                          trail_p=[np.array([-5.0, 1.0, 0.0]), np.array([5.0, 1.0, 0.0])],
                          motion=None, pose=np.array([5.0, 1.0, 0.0]))
    sim = SimpleNamespace(robots={"op": person, "uav1": uav})
    got = social(sim, 10.0)  # type: ignore[arg-type]
    assert got["human_min_distance"] == pytest.approx(1.0)
    assert got["human_close_s"] == pytest.approx(2 * np.sqrt(1.2**2 - 1.0), abs=0.1)


def test_the_social_metrics_arithmetic_is_numpys_bit_for_bit() -> None:
    """The velocities are ``np.gradient``'s and a trail out of time order is sorted stably
    before it is interpolated, bit for bit, on random paths."""
    from types import SimpleNamespace

    from astralis_des.simulation.metrics import STEP, _gradient, _track

    rng = np.random.default_rng(11)
    for n in (2, 3, 7, 500):
        path = rng.normal(0.0, 5.0, (n, 3))
        assert _gradient(path).tobytes() == np.gradient(path, STEP, axis=0).tobytes()
    times = np.arange(0.0, 20.0, STEP)
    trail_t = [0.0, 4.0, 3.0, 3.0, 9.5, 15.0]
    trail_p = [rng.normal(0.0, 3.0, 3) for _ in trail_t]
    robot = SimpleNamespace(trail_t=trail_t, trail_p=trail_p, motion=None, pose=trail_p[-1])
    order = np.argsort(trail_t, kind="stable")
    tt, pp = np.asarray(trail_t)[order], np.asarray(trail_p)[order]
    expected = np.column_stack([np.interp(times, tt, pp[:, k]) for k in range(3)])
    got = _track(SimpleNamespace(robots={"r": robot}), "r", times, 20.0)  # type: ignore[arg-type]
    assert got.tobytes() == expected.tobytes()


def test_a_run_ended_within_its_first_tenth_of_a_second_has_its_metrics() -> None:
    """A served mission ended at t = 0.01 s (the API's end): its metrics have no closest
    approach to measure, not a traceback in the server's thread (np.gradient of one sample)."""
    mission = load_mission(ROOT / "missions" / "urban_search.yaml").with_changes(
        outputs={"events": False, "summary": False, "recording": False})
    sim = Simulation(mission)
    sim.advance(until=0.01)
    result = sim.finish()
    assert result.outcome == "interrupted" and result.end_time == pytest.approx(0.01)
    assert result.metrics["human_min_distance"] is None
    assert result.metrics["human_close_s"] is None
    assert result.metrics["time_to_find"] is None and result.metrics["found"] is False


def test_allocation_metrics_of_the_default_mission_match_its_event_log(tmp_path: Path) -> None:
    from astralis_des.simulation.metrics import allocation_metrics

    mission = load_mission(ROOT / "missions" / "urban_search.yaml")
    sim = Simulation(mission, out_dir=tmp_path)
    result = sim.run()
    events = [json.loads(line) for line in (tmp_path / "events.jsonl").read_text().splitlines()]
    searches = [e for e in events if e["kind"] == "task_finished" and e["room"]
                and e["action"] != "move"
                and e["status"] == "succeeded"]
    got = allocation_metrics(sim, result.rounds, result.end_time, 0.5, 0.5)
    assert got["makespan"] == pytest.approx(max(e["t"] for e in searches), abs=1e-6)
    last = {e["room"]: e["t"] for e in searches}
    assert got["completion_sum"] == pytest.approx(sum(last.values()), abs=1e-5)
    per_robot = [sum(1 for e in searches if e["robot"] == m.id) for m in mission.spec.team]
    assert got["rooms_per_robot"] == pytest.approx(sum(per_robot) / len(per_robot))
    rounds = [e for e in events if e["kind"] == "assignment"]
    kinds = {m.id: m.kind for m in mission.spec.team}
    human = sum(any(kinds[p["agent"]] == "human" and
                    dict(zip(r["rooms"], r["risk"], strict=True))[p["room"]] >= 0.5
                    for p in r["matching"]) for r in rounds)
    assert got["human_high_risk_rounds"] == pytest.approx(human / len(rounds))
    assert got["infeasible_rounds"] == 0


def test_a_study_varies_the_baselines_options(tmp_path: Path) -> None:
    """``options`` is a study parameter: CBBA with bundles of one room against three."""
    from astralis_des.studies import make_study, run_study

    study = make_study(ROOT / "missions" / "urban_search.yaml", name="bundles", scenarios=2,
                       seed=3, evaluate="mission",
                       set={"strategy": "cbba", "fidelity": "kinematic"},
                       vary={"options": [{"bundle": 1}, {"bundle": 3}]})
    rows = run_study(study, workers=1).rows
    assert [r["variant"] for r in rows] == ["bundle=1", "bundle=3"] * 2
    assert all(r["status"] == "ok" for r in rows)
    one = [r for r in rows if "bundle=1" in r["variant"]]
    three = [r for r in rows if "bundle=3" in r["variant"]]
    assert [r["rounds"] for r in one] != [r["rounds"] for r in three]  # more rounds of 1 room
