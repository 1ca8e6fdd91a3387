"""Fidelity benchmark: the same scenarios and strategies in kinematic and physics fidelity.

    python tools/bench/bench_fidelity.py [--scenarios 30] [--workers 2] [--json OUT.json]

The scenarios are the first N of ``studies/outcomes_physics.yaml`` (the outcome study's draws:
starts outdoors, each room's risk and messiness, the target, the furniture), each under the
three strategies. Each mission runs in both fidelities. Printed per fidelity:

- failed tasks per mission (median, mean, max) and by cause (the failure's message with its
  numbers taken out), crashes (``fault`` events of a crashed robot), missions that ran to their
  time limit, the found share and the time to find;
- the share of (scenario, strategy) pairs whose outcome, finder and rooms searched agree
  between the two fidelities;
- the wall time of the runs, and the real-time factor of the physics missions.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

STUDY = ROOT / "studies" / "outcomes_physics.yaml"
FIDELITIES = ("kinematic", "physics")


def cause(message: str) -> str:
    """A failure's message without its numbers, room ids and coordinates: its cause."""
    text = re.sub(r"\[[^\]]*\]", "[...]", message)
    text = re.sub(r"\b[A-Z]\.\d\.\d\.\d\b", "ROOM", text)
    text = re.sub(r"-?\d+(\.\d+)?", "N", text)
    return text


def one(job: tuple[int, str, str]) -> dict[str, Any]:
    """Scenario ``index`` under ``strategy`` in ``fidelity``: what the benchmark tabulates."""
    from astralis_des.simulation import Simulation
    from astralis_des.studies import load_study
    from astralis_des.studies.eval_mission import scenario_mission

    index, strategy, fidelity = job
    study = load_study(STUDY)
    variant = next(v for v in study.variants if v.setting.strategy == strategy)
    setting = variant.setting
    scenario = study.scenario(index)
    mission = scenario_mission(study, scenario, setting, outputs=False)
    mission = mission.with_changes(fidelity=fidelity)
    t0 = time.perf_counter()
    sim = Simulation(mission)
    result = sim.run()
    wall = time.perf_counter() - t0
    failures = [r for r in result.events
                if r["kind"] == "task_finished" and r["status"] == "failed"]
    crashes = [r for r in result.events if r["kind"] == "fault"
               and str(r.get("reason", "")).startswith("crash")]
    return {
        "scenario": index, "strategy": strategy, "fidelity": fidelity,
        "outcome": result.outcome, "found_by": result.found_by,
        "time_to_find": result.time_to_find, "end_time": result.end_time,
        "rooms_searched": sorted(result.rooms_searched),
        "failed": [cause(r["message"]) for r in failures],
        "failed_raw": [f"{r['t']:.1f} {r.get('robot')} {r['action']} {r['room']}: "
                       f"{r['message']}" for r in failures],
        "crashes": len(crashes), "wall": wall,
    }


def summarise(rows: list[dict[str, Any]], fidelity: str) -> list[str]:
    mine = [r for r in rows if r["fidelity"] == fidelity]
    failed = [len(r["failed"]) for r in mine]
    causes = Counter(c for r in mine for c in r["failed"])
    found = [r for r in mine if r["outcome"] == "found"]
    times = [r["time_to_find"] for r in found]
    simulated = sum(r["end_time"] for r in mine)
    wall = sum(r["wall"] for r in mine)
    lines = [
        f"## {fidelity}: {len(mine)} missions",
        f"failed tasks a mission: median {statistics.median(failed):g}, "
        f"mean {statistics.fmean(failed):.2f}, max {max(failed)}; total {sum(failed)}",
        f"crashes: {sum(r['crashes'] for r in mine)} "
        f"(in {sum(1 for r in mine if r['crashes'])} missions)",
        f"ran to the time limit: {sum(r['outcome'] == 'time_limit' for r in mine)}",
        f"found: {len(found)}/{len(mine)} ({len(found) / len(mine):.0%}); time to find: "
        f"mean {statistics.fmean(times) if times else float('nan'):.1f} s, "
        f"median {statistics.median(times) if times else float('nan'):.1f} s",
        f"wall: {wall:.0f} s for {simulated:.0f} simulated s "
        f"({simulated / wall:.1f}x real time)",
    ]
    if causes:
        lines.append("failures by cause:")
        lines += [f"  {n:4d}  {c}" for c, n in causes.most_common()]
    return lines


def agreement(rows: list[dict[str, Any]]) -> list[str]:
    by = {(r["scenario"], r["strategy"], r["fidelity"]): r for r in rows}
    pairs = [(by[(s, g, "kinematic")], by[(s, g, "physics")])
             for (s, g, f) in by if f == "kinematic" and (s, g, "physics") in by]
    n = len(pairs)
    outcome = sum(k["outcome"] == p["outcome"] for k, p in pairs)
    finder = sum(k["outcome"] == p["outcome"] and k["found_by"] == p["found_by"]
                 for k, p in pairs)
    searched = sum(k["rooms_searched"] == p["rooms_searched"] for k, p in pairs)
    timed = sum(k["outcome"] == p["outcome"] and k["found_by"] == p["found_by"] and (
        k["time_to_find"] is None or p["time_to_find"] is None
        or abs(p["time_to_find"] - k["time_to_find"]) <= 0.2 * k["time_to_find"])
        for k, p in pairs)
    kin = sum(k["outcome"] == "found" for k, _ in pairs)
    phy = sum(p["outcome"] == "found" for _, p in pairs)
    return [
        f"## agreement over {n} (scenario, strategy) pairs",
        f"found: kinematic {kin / n:.0%}, physics {phy / n:.0%} "
        f"({(phy - kin) / n * 100:+.0f} points)",
        f"same outcome: {outcome / n:.0%}; same outcome and finder: {finder / n:.0%}; "
        f"same rooms searched: {searched / n:.0%}",
        f"same detection (outcome, finder, time to find within 20%): {timed / n:.0%}",
    ]


def fast_worker() -> None:
    """A worker's start-up: it runs many missions, so on the compiled kernels (the same
    outcomes; numba's import repaid) where numba is installed."""
    from astralis_des import compiled

    compiled.enable()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--scenarios", type=int, default=30)
    parser.add_argument("--first", type=int, default=0, help="index of the first scenario")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--strategies", default="naive,mixed,greedy")
    parser.add_argument("--fidelities", default=",".join(FIDELITIES))
    parser.add_argument("--json", type=Path, help="write every row here")
    args = parser.parse_args()
    jobs = [(i, s, f) for f in args.fidelities.split(",")
            for i in range(args.first, args.first + args.scenarios)
            for s in args.strategies.split(",")]
    jobs.sort(key=lambda j: j[2] != "physics")  # the long ones first
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers, initializer=fast_worker) as pool:
        rows = list(pool.map(one, jobs, chunksize=1))
    rows.sort(key=lambda r: (r["fidelity"], r["scenario"], r["strategy"]))
    print(f"# {args.scenarios} scenarios x {len(args.strategies.split(','))} strategies, "
          f"{time.perf_counter() - t0:.0f} s on {args.workers} workers")
    for fidelity in args.fidelities.split(","):
        print("\n".join(summarise(rows, fidelity)))
    if len(args.fidelities.split(",")) == 2:
        print("\n".join(agreement(rows)))
    worst = sorted((r for r in rows if r["fidelity"] == "physics"),
                   key=lambda r: -len(r["failed"]))[:5]
    for r in worst:
        if r["failed"]:
            print(f"scenario {r['scenario']} {r['strategy']}: {len(r['failed'])} failed, "
                  f"{r['outcome']}; first: {r['failed_raw'][0]}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
