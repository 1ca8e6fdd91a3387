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

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.mission.loader import load_mission  # noqa: E402
from astralis_des.studies.falsify import Falsify, base_run, run_falsify  # noqa: E402
from astralis_des.studies.falsify_report import best_so_far  # noqa: E402
from astralis_des.studies.falsify_space import load_space  # noqa: E402


def search(mission: object, space: object, metric: str, sampler: str, trials: int, seed: int,
           workers: int) -> tuple[float | None, float, int]:
    """The worst score of ``trials`` of ``sampler``, the wall time, the trial that found it."""
    f = Falsify(mission, space, "mixed", metric, trials, sampler=sampler,  # type: ignore[arg-type]
                seed=seed, baseline=False)
    t0 = time.perf_counter()
    result = run_falsify(f, workers=workers)
    wall = time.perf_counter() - t0
    curve = best_so_far(result, "optimiser")
    best = curve[-1] if curve else None
    at = next((i + 1 for i, v in enumerate(curve) if v == best), 0)
    return best, wall, at


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--random", type=int, default=1000, help="random scenarios")
    parser.add_argument("--trials", type=int, default=200, help="optimised trials")
    parser.add_argument("--sampler", default="tpe")
    parser.add_argument("--seeds", default="0", help="comma-separated samplers' seeds")
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
    for metric in args.metrics.split(","):
        for seed in (int(s) for s in args.seeds.split(",")):
            worst_r, wall_r, at_r = search(mission, space, metric, "random", args.random, seed,
                                           args.workers)
            worst_o, wall_o, at_o = search(mission, space, metric, args.sampler, args.trials,
                                           seed, args.workers)
            ok = worst_o is not None and worst_r is not None and worst_o >= worst_r \
                and wall_o < wall_r
            wins += ok
            runs += 1
            print(f"{metric} seed {seed}: random {args.random}: worst {worst_r:.2f} (trial "
                  f"{at_r}) in {wall_r:.1f} s; {args.sampler} {args.trials}: worst "
                  f"{worst_o:.2f} (trial {at_o}) in {wall_o:.1f} s; wall ratio "
                  f"{wall_o / wall_r:.2f}; {'met' if ok else 'NOT met'}")
    print(f"goal met in {wins} of {runs}")


if __name__ == "__main__":
    main()
