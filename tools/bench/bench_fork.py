"""Fork benchmark: the default mission's run against forks of it at round 3.

    python tools/bench/bench_fork.py [--repeat 7] [--no-physics]

A fork runs the mission again up to the fork point (no snapshot: the run is deterministic),
so its price is that of a run. Printed, each the median of ``--repeat`` runs in this process
taking turns (after a warm-up run of each, so that what a process keeps between runs is
there for all), with the outputs written (events, summary, recording) as ``astralis run``
writes them:

- the original run (``mixed``);
- a fork at round 3 that changes nothing the run reads (the same weights): the price of
  forking alone, the run otherwise the original;
- the fork at round 3 to ``greedy``, and to ``cbba`` (which plans every room left and
  searches longer before it finds the target: its simulated time is printed beside it).

Ratios are to the original's time measured in the same run, and per simulated second; the
goal: a fork at round 3 under 1.5x the original's. Physics: one run of each (``--repeat``
does not apply; a run takes seconds).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des import Simulation, load_mission  # noqa: E402
from astralis_des.mission.loader import Mission  # noqa: E402
from astralis_des.simulation.result import RunResult  # noqa: E402

FORKS = {  # label: the changes at round 3
    "fork round:3, nothing changed": {"assignment.weights.risk.human": 10.0},
    "fork round:3 -> greedy": {"assignment.strategy": "greedy"},
    "fork round:3 -> cbba": {"assignment.strategy": "cbba"},
}


def timed(run: Callable[[Path], RunResult]) -> tuple[float, RunResult]:
    """The wall time of one run into a fresh folder, and its result."""
    with tempfile.TemporaryDirectory() as folder:
        t0 = time.perf_counter()
        result = run(Path(folder) / "run")
        return time.perf_counter() - t0, result


def table(mission: Mission, repeat: int) -> None:
    """Each variant's median time; the variants take turns, so that a process warming up
    (or a machine busy for a while) weighs on all alike."""
    runs: dict[str, Callable[[Path], RunResult]] = {
        "original run (mixed)": lambda out: Simulation(mission, out_dir=out).run()}
    for label, changes in FORKS.items():
        runs[label] = lambda out, c=changes: Simulation(mission, out_dir=out).fork("round:3", c)
    for run in runs.values():  # warm-up: the world's caches, the imports
        run_once = timed(run)
    del run_once
    times: dict[str, list[float]] = {label: [] for label in runs}
    results: dict[str, RunResult] = {}
    for _ in range(repeat):
        for label, run in runs.items():
            seconds, results[label] = timed(run)
            times[label].append(seconds)
    print(f"{mission.spec.fidelity}, median of {repeat}, outputs written:")
    base = statistics.median(times["original run (mixed)"])
    per_s = base / results["original run (mixed)"].end_time
    for label, result in results.items():
        seconds = statistics.median(times[label])
        print(f"  {label:30s} {seconds * 1000:9.1f} ms  {seconds / base:5.2f}x   "
              f"{result.end_time:6.1f} s simulated ({seconds / result.end_time / per_s:4.2f}x "
              f"per simulated s), {len(result.events)} events")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--no-physics", action="store_true", help="kinematic only")
    args = parser.parse_args()
    mission = load_mission(ROOT / "missions" / "urban_search.yaml")
    table(mission, args.repeat)
    if not args.no_physics:
        table(mission.with_changes(fidelity="physics"), 1)


if __name__ == "__main__":
    main()
