"""Allocation benchmark: the wall time of one assignment round per strategy, and the baselines
study.

    python tools/bench/bench_allocation.py [--repeat 200] [--study] [--workers 2]

A round is the default team (two UAVs, the UGV, the person) at the default mission's starts
against one segment of building A (3 rooms, drawn risk and messiness) and, for the planners of
whole queues, against all 18 rooms of the building. Goals (issue 21): under 1 ms median for
mixed, hard, auction and random on a segment; under 20 ms for cbba; milp on 4 agents x 18
rooms under 1 s with a proven gap of at most 1%. ``--study`` times ``studies/baselines.yaml``
(1,000 scenarios x 6 strategies, kinematic; goal under 4 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.assignment import Agent, RoomInfo, Weights, assign  # noqa: E402
from astralis_des.mission.loader import load_mission  # noqa: E402

STRATEGIES = ("naive", "mixed", "greedy", "hard", "random", "auction", "cbba", "milp")


def problems(n: int, all_rooms: bool) -> list[tuple[list[Agent], list[RoomInfo]]]:
    mission = load_mission(ROOT / "missions" / "urban_search.yaml")
    world = mission.world
    team = [Agent(m.id, m.kind, world.rooms[m.start].center if isinstance(m.start, str)
                  else (float(m.start[0]), float(m.start[1]), float(m.start[2])))
            for m in mission.spec.team]
    segments = mission.searched_segments()
    rng = np.random.default_rng(1)
    out = []
    for k in range(n):
        ids = ([r for s in segments for r in world.segments[s].rooms] if all_rooms
               else list(world.segments[segments[k % len(segments)]].rooms))
        rooms = []
        for rid in ids:
            rooms.append(RoomInfo(rid, world.rooms[rid].center, float(rng.random()),
                                  float(rng.random()), world.rooms[rid].area))
        out.append((team, rooms))
    return out


def timed(strategy: str, cases: list[tuple[list[Agent], list[RoomInfo]]],
          weights: Weights) -> tuple[list[float], list[dict[str, object]]]:
    times, infos = [], []
    for seed, (team, rooms) in enumerate(cases):
        t0 = time.perf_counter()
        plan = assign(team, rooms, weights, strategy=strategy,
                      rng=np.random.default_rng(seed))
        times.append(time.perf_counter() - t0)
        infos.append(plan.info)
    return times, infos


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=200)
    parser.add_argument("--study", action="store_true")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    weights = Weights({"human": 10, "uav": 5, "ugv": 3}, {"human": 5, "uav": 0, "ugv": 10})
    segment, building = problems(args.repeat, False), problems(max(args.repeat // 10, 5), True)
    print(f"{'strategy':9} {'segment (3 rooms) median':>25} {'p90':>9}   "
          f"{'building (18 rooms) median':>27} {'p90':>9}")
    for strategy in STRATEGIES:
        seg, _ = timed(strategy, segment, weights)
        whole, infos = timed(strategy, building, weights)
        p90 = (lambda x: sorted(x)[int(0.9 * (len(x) - 1))])  # noqa: E731
        print(f"{strategy:9} {statistics.median(seg) * 1e3:22.3f} ms {p90(seg) * 1e3:6.3f} ms"
              f"   {statistics.median(whole) * 1e3:24.3f} ms {p90(whole) * 1e3:6.3f} ms")
        if strategy == "milp":
            gaps = [float(str(i["gap"])) for i in infos if i.get("gap") is not None]
            hit = sum(bool(i.get("hit_limit")) for i in infos)
            print(f"  milp, 4 agents x 18 rooms: largest gap {max(gaps):.2%}, "
                  f"{hit} of {len(infos)} hit the time limit")
    if args.study:
        from astralis_des.studies import load_study, run_study

        study = load_study(ROOT / "studies" / "baselines.yaml")
        t0 = time.perf_counter()
        result = run_study(study, workers=args.workers)
        wall = time.perf_counter() - t0
        print(f"baselines study: {len(result.rows):,} missions in {wall:.1f} s on "
              f"{args.workers} workers ({len(result.rows) / wall:.1f} missions/s)")


if __name__ == "__main__":
    main()
