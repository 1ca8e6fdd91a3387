"""Detection benchmark: missions that searched every room and still did not find the target.

    python tools/bench/bench_detection.py [--scenarios 1000] [--workers 2]

Runs ``studies/outcomes.yaml`` (kinematic fidelity; its scenarios under each strategy) and
prints, per strategy, the found share, the share of missions ending ``not_found`` with every
room searched, and each such mission classified by why the target was never detected. The
cause is the furthest of these tests that some look at the target's room passed (every robot's
trail, every 0.25 m, its camera facing its travel, and round for a camera that pans):

- ``outside every frustum``: no part of the target's box was ever in a frame;
- ``too few pixels``: in a frame, but it would show fewer than ``min_pixels`` even unhidden;
- ``only through walls``: big enough, but walls and slabs hid it;
- ``occluded by furniture``: the walls let it be seen, the furniture and avatars did not;
- ``missed between looks``: the model detects it from some sample of the trail (the
  mission's own looks fell elsewhere: a patrolling target, a look-around not taken).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

STUDY = ROOT / "studies" / "outcomes.yaml"
STEP = 0.25  # m between looks along a trail


def looks(robot: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, camera headings and times along a robot's trail."""
    from astralis_des.view import LOOK_AROUND, travel_headings
    from astralis_des.world.geometry import resample

    t = np.asarray(robot.trail_t, dtype=float)
    p = np.asarray(robot.trail_p, dtype=float)
    if len(p) < 2:
        return np.zeros((0, 3)), np.zeros(0), np.zeros(0)
    pts, s = resample(p, STEP)
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    times = np.interp(s, along, t)
    heads = travel_headings(pts, robot.heading)
    if robot.view.look_around:
        turn = np.arange(LOOK_AROUND) * (2 * np.pi / LOOK_AROUND)
        pts = np.repeat(pts, LOOK_AROUND + 1, axis=0)
        heads = (heads[:, None] + np.concatenate([[0.0], turn])[None, :]).ravel()
        times = np.repeat(times, LOOK_AROUND + 1)
    return pts, heads, times


def classify(sim: Any) -> str:
    """Why the target was never detected (see the module's docstring)."""
    from astralis_des.detection import predict_pixels
    from astralis_des.sensing import in_frame

    stage = 0
    size = np.asarray(sim.target.size, dtype=float)
    for robot in sim.robots.values():
        if robot.view is None:
            continue
        pts, heads, times = looks(robot)
        if not len(pts):
            continue
        targets = sim.target.positions_at(times)
        every = np.arange(len(pts))
        view = robot.view
        i, _ = in_frame(view, pts, heads, targets, size, every, every)
        if not len(i):
            continue
        stage = max(stage, 1)
        big = predict_pixels(view, pts[i], heads[i], targets[i], size, None) >= view.min_pixels
        i = i[big]
        if not len(i):
            continue
        stage = max(stage, 2)
        ok = predict_pixels(view, pts[i], heads[i], targets[i], size,
                            sim.world.line_of_sight) >= view.min_pixels
        i = i[ok]
        if not len(i):
            continue
        stage = max(stage, 3)
        seen = predict_pixels(view, pts[i], heads[i], targets[i], size,
                              sim.scene.line_of_sight) >= view.min_pixels
        if seen.any():
            stage = 4
    return ("outside every frustum", "too few pixels", "only through walls",
            "occluded by furniture", "missed between looks")[stage]


def one(job: tuple[int, str]) -> dict[str, Any]:
    from astralis_des.simulation import Simulation
    from astralis_des.studies import load_study
    from astralis_des.studies.eval_mission import scenario_mission

    index, strategy = job
    study = load_study(STUDY)
    setting = next(v for v in study.variants if v.setting.strategy == strategy).setting
    mission = scenario_mission(study, study.scenario(index), setting, outputs=False)
    sim = Simulation(mission)
    result = sim.run()
    every = set(result.rooms_searched) >= set(mission.searched_rooms())
    row: dict[str, Any] = {"scenario": index, "strategy": strategy, "outcome": result.outcome,
                           "all_searched": every, "cause": None,
                           "undercovered": sum(e["kind"] == "room_undercovered"
                                               for e in result.events)}
    if result.outcome == "not_found" and every:
        row["cause"] = classify(sim)
        row["target_room"] = result.rooms.get(result.target["room"])
    return row


def fast_worker() -> None:
    """A worker's start-up: it runs many missions, so on the compiled kernels (the same
    outcomes; numba's import repaid) where numba is installed."""
    from astralis_des import compiled

    compiled.enable()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--scenarios", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--strategies", default="naive,mixed,greedy")
    args = parser.parse_args()
    strategies = args.strategies.split(",")
    jobs = [(i, s) for i in range(args.scenarios) for s in strategies]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers, initializer=fast_worker) as pool:
        rows = list(pool.map(one, jobs, chunksize=8))
    print(f"# {args.scenarios} scenarios x {len(strategies)} strategies (kinematic), "
          f"{time.perf_counter() - t0:.0f} s on {args.workers} workers")
    for strategy in strategies:
        mine = [r for r in rows if r["strategy"] == strategy]
        n = len(mine)
        found = sum(r["outcome"] == "found" for r in mine)
        missed = [r for r in mine if r["cause"] is not None]
        requeued = sum(r["undercovered"] for r in mine)
        print(f"## {strategy}: found {found}/{n} ({found / n:.1%}); not_found with every room "
              f"searched {len(missed)} ({len(missed) / n:.1%}, goal <= 3%); rooms seen too "
              f"little and re-queued: {requeued / n:.2f} a mission")
        for cause, count in Counter(r["cause"] for r in missed).most_common():
            print(f"  {count:4d}  {cause}")


if __name__ == "__main__":
    main()
