"""Falsify benchmark (issue 44): on the kinematic default mission (missions/urban_search.yaml,
strategy mixed), 1,000 random scenarios against 200 optimised trials, both on 2 workers, for
the human's seconds in high-risk rooms and the time to find.

    python tools/bench/bench_falsify.py [--workers 2] [--random 1000] [--trials 200]
        [--sampler tpe] [--seeds 0] [--metrics human_high_risk_s,time_to_find]

The issue's number: the optimised trials find a scenario at least as bad as the worst of the
random ones, in less wall time. Both searches run here, one after the other, in the same
space (the mission's own ranges) and on the same worker pool size, so the ratio is measured in
one run; absolute times move with the machine's load (other jobs on its 2 cores).
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.mission.loader import load_mission  # noqa: E402
from astralis_des.studies.falsify import Falsify, base_run, run_falsify  # noqa: E402
from astralis_des.studies.falsify_eval import badness  # noqa: E402
from astralis_des.studies.falsify_space import load_space  # noqa: E402


def search(mission: Any, space: Any, metrics: list[str], sampler: str, trials: int,
           seed: int, workers: int) -> tuple[dict[str, tuple[float | None, int]], float]:
    """Each metric's worst score over ``trials`` of ``sampler`` (searching for the first
    metric; a random search reads every metric off the same trials) with the trial that
    found it, and the wall time."""
    f = Falsify(mission, space, "mixed", metrics[0], trials, sampler=sampler, seed=seed,
                baseline=False)
    t0 = time.perf_counter()
    result = run_falsify(f, workers=workers)
    wall = time.perf_counter() - t0
    limit = mission.spec.time_limit
    worst: dict[str, tuple[float | None, int]] = {}
    for metric in metrics:
        scores = [badness(metric, r[f"mixed.{metric}"], limit) for r in result.rows]
        known = [(v, i + 1) for i, v in enumerate(scores) if v is not None]
        best = max(v for v, _ in known) if known else None
        worst[metric] = (best, next((i for v, i in known if v == best), 0))
    return worst, wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--random", type=int, default=1000, help="random scenarios")
    parser.add_argument("--trials", type=int, default=200, help="optimised trials")
    parser.add_argument("--sampler", default="tpe")
    parser.add_argument("--seeds", default="0",
                        help="comma-separated seeds (TPE's; random's is 10,000 more)")
    parser.add_argument("--metrics", default="human_high_risk_s,time_to_find")
    args = parser.parse_args()
    logging.disable(logging.WARNING)  # UAVs landing where they are: not this benchmark's
    mission = load_mission(ROOT / "missions" / "urban_search.yaml")
    base = base_run(mission, "mixed")
    space = load_space(None, mission, strategies=["mixed"], fault_until=base["end_time"])
    print(f"urban_search, kinematic, strategy mixed; {len(space.dims)} parameters; "
          f"{args.workers} workers")
    wins = 0
    runs = 0
    metrics = args.metrics.split(",")
    for seed in (int(s) for s in args.seeds.split(",")):
        random, wall_r = search(mission, space, metrics, "random", args.random,
                                seed + 10_000, args.workers)
        print(f"seed {seed}: random {args.random} trials in {wall_r:.1f} s")
        for metric in metrics:
            found, wall_o = search(mission, space, [metric], args.sampler, args.trials, seed,
                                   args.workers)
            (worst_r, at_r), (worst_o, at_o) = random[metric], found[metric]
            ok = worst_o is not None and worst_r is not None and worst_o >= worst_r \
                and wall_o < wall_r
            wins += ok
            runs += 1
            print(f"  {metric}: random worst {worst_r:.2f} (trial {at_r}); {args.sampler} "
                  f"{args.trials}: worst {worst_o:.2f} (trial {at_o}) in {wall_o:.1f} s; wall "
                  f"ratio {wall_o / wall_r:.2f}; {'met' if ok else 'NOT met'}", flush=True)
    print(f"goal met in {wins} of {runs}")


if __name__ == "__main__":
    main()
