"""Tune benchmark: the Table V fit (tunes/table5_fit.yaml: 60 trials of 2 x 1,000 assignment
problems) and, with --front, the two-objective mission tune (tunes/mission_front.yaml: 40
trials of 200 kinematic missions).

    python tools/bench/bench_tune.py [--workers 2] [--front] [--keep DIR]

Goals (issue 20): the Table V tune under 60 s on 2 cores; the mission front under 10 minutes
with at least 5 points. Beside the wall time it prints the time in the studies themselves (the
rest is the sampler, forking the workers and writing the folder).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.studies.tune import run_tune  # noqa: E402
from astralis_des.studies.tune_spec import load_tune  # noqa: E402


def one(name: str, workers: int, keep: Path | None) -> None:
    tune = load_tune(ROOT / "tunes" / f"{name}.yaml")
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        result = run_tune(tune, workers=workers, out=keep / name if keep else tmp)
        wall = time.perf_counter() - t0
    studies = sum(r["seconds"] for r in result.rows)
    runs = result.study_rows
    print(f"{name}: {len(result.rows)} trials, {runs:,} study rows, {wall:.1f} s on {workers} "
          f"workers ({runs / wall:,.0f} rows/s); in the studies {studies:.1f} s "
          f"({studies / wall:.0%}); sampler, workers and folder {wall - studies:.1f} s")
    if result.tune.spec.targets:
        print(f"  best largest |z| {result.best[0]['score']:.2f}; {len(result.fits())} trials "
              "fit all targets")
    else:
        print(f"  front: {len(result.best)} points")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--front", action="store_true", help="also the mission front")
    parser.add_argument("--keep", type=Path, help="write each tune's folder under KEEP")
    args = parser.parse_args()
    one("table5_fit", args.workers, args.keep)
    if args.front:
        one("mission_front", args.workers, args.keep)


if __name__ == "__main__":
    main()
