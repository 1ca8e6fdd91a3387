"""Clutter benchmark: every room of the default world at messiness 1, against the 2 s goal.

    python tools/bench/bench_clutter.py [--repeat 5] [--seed 0]

Prints the median wall time of ``place_world`` (free space of each room, then placement), the
items placed by kind and what was skipped, with the reasons.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.world.build import load_world  # noqa: E402
from astralis_des.world.catalogue import default_catalogue  # noqa: E402
from astralis_des.world.clutter import Clutter, place_world  # noqa: E402

GOAL_S = 2.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    world = load_world(ROOT / "worlds" / "urban_default.yaml")
    catalogue = default_catalogue()
    messiness = dict.fromkeys(world.rooms, 1.0)

    times: list[float] = []
    clutter = Clutter()
    for k in range(args.repeat):
        t0 = time.perf_counter()
        clutter = place_world(world, messiness, args.seed + k, catalogue)
        times.append(time.perf_counter() - t0)
    median = statistics.median(times)
    verdict = "ok" if median < GOAL_S else "TOO SLOW"
    print(f"place_world, {len(messiness)} rooms at messiness 1: median {median:.3f} s of "
          f"{args.repeat} (min {min(times):.3f}, max {max(times):.3f}); goal < {GOAL_S:g} s: "
          f"{verdict}")
    print(f"  per room: {1000 * median / len(messiness):.1f} ms")
    kinds = Counter(p.kind for p in clutter.placed)
    print(f"  placed {len(clutter.placed)} (last run): "
          + ", ".join(f"{kind} {n}" for kind, n in sorted(kinds.items())))
    reasons = Counter((kind, reason) for _, kind, reason in clutter.skipped)
    print(f"  skipped {len(clutter.skipped)}" + (":" if reasons else ""))
    for (kind, reason), n in sorted(reasons.items()):
        print(f"    {n} x {kind}: {reason}")


if __name__ == "__main__":
    main()
