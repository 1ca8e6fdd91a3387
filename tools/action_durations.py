"""The seconds per square metre of floor each Table IV action takes in the kinematic fidelity:
the figures ``astralis_des.assignment.durations`` gives the queue planners.

    python tools/action_durations.py [--scenarios 40]

Runs the first scenarios of ``studies/outcomes.yaml`` under each of its strategies and prints,
per kind and action, the searches that succeeded, their mean seconds, and seconds per m^2
(mean and standard deviation) beside the table's value.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from astralis_des.assignment.durations import seconds_per_m2  # noqa: E402
from astralis_des.simulation import Simulation  # noqa: E402
from astralis_des.studies import load_study  # noqa: E402
from astralis_des.studies.eval_mission import scenario_mission  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--scenarios", type=int, default=40)
    args = parser.parse_args()
    study = load_study(ROOT / "studies" / "outcomes.yaml")
    seen: dict[tuple[str, str], list[tuple[float, float]]] = defaultdict(list)
    for index in range(args.scenarios):
        scenario = study.scenario(index)
        for variant in study.variants:
            sim = Simulation(scenario_mission(study, scenario, variant.setting, False))
            sim.run()
            for task, res in sim.finished:
                if task.action == "move" or not res.ok or not task.room:
                    continue
                kind = sim.robots[task.robot].kind
                seen[(kind, task.action)].append((sim.world.rooms[task.room].area,
                                                  res.end - res.start))
    print(f"{'kind':6} {'action':17} {'searches':>8} {'mean s':>7} {'s/m2':>6} {'sd':>6} "
          f"{'table':>6}")
    for (kind, action), rows in sorted(seen.items()):
        a = np.array(rows)
        per = a[:, 1] / a[:, 0]
        print(f"{kind:6} {action:17} {len(a):8d} {a[:, 1].mean():7.1f} {per.mean():6.3f} "
              f"{per.std():6.3f} {seconds_per_m2(kind, action):6.3f}")


if __name__ == "__main__":
    main()
