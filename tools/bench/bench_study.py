"""Study benchmark: Table V's 2 x 1,000 assignment problems, and 1,000 kinematic missions on
1 and 2 processes (parallel efficiency), optionally on Ray.

    python tools/bench/bench_study.py [--missions 1000] [--workers 2] [--repeat 5] [--ray]

Goals (issue 8): Table V under 1 s; 1,000 kinematic missions on 2 workers under 60 s with a
parallel efficiency (time on 1 / (workers x time on N)) of at least 80%.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.studies import load_study, run_study  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--missions", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--ray", action="store_true", help="also run the missions on Ray")
    args = parser.parse_args()

    table5 = load_study(ROOT / "studies" / "table5.yaml")
    run_study(table5.with_changes(scenarios=20), workers=1)  # imports, caches
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        result = run_study(table5, workers=1)
        times.append(time.perf_counter() - t0)
    problems = len(result.rows)
    print(f"Table V, {problems:,} assignment problems, 1 process: median "
          f"{statistics.median(times):.3f} s (goal < 1 s), "
          f"{problems / statistics.median(times):,.0f} problems/s")
    t0 = time.perf_counter()
    run_study(table5, workers=args.workers)
    print(f"Table V, {args.workers} processes (pool start-up included): "
          f"{time.perf_counter() - t0:.3f} s")

    missions = load_study(ROOT / "studies" / "outcomes.yaml").with_changes(
        scenarios=args.missions, vary={"strategy": ["mixed"]})
    print(f"{args.missions:,} kinematic missions (studies/outcomes.yaml, mixed), "
          "recording off, pool start-up included:")
    walls: dict[int, float] = {}
    for workers in sorted({1, args.workers}):
        t0 = time.perf_counter()
        result = run_study(missions, workers=workers)
        walls[workers] = time.perf_counter() - t0
        simulated = sum(r["end_time"] for r in result.rows if r["status"] == "ok")
        line = (f"  {workers} process{'es' if workers > 1 else ''}: {walls[workers]:.1f} s, "
                f"{args.missions / walls[workers]:.1f} missions/s, {result.failed} failed, "
                f"{simulated / walls[workers]:,.0f} simulated s per wall s")
        if workers > 1:
            efficiency = walls[1] / (workers * walls[workers])
            line += (f" (goal < 60 s); speed-up {walls[1] / walls[workers]:.2f}, parallel "
                     f"efficiency {efficiency:.0%} (goal >= 80%)")
        print(line)
    if args.ray:
        t0 = time.perf_counter()
        run_study(missions, workers=args.workers, backend="ray")
        wall = time.perf_counter() - t0
        print(f"  Ray, local instance of {args.workers} CPUs (its start-up included): "
              f"{wall:.1f} s, efficiency against 1 process {walls[1] / (args.workers * wall):.0%}")


if __name__ == "__main__":
    main()
