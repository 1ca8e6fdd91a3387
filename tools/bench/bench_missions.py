"""What a user waits for on each shipped mission: ``astralis run missions/NAME.yaml``.

    python tools/bench/bench_missions.py [--repeat 3] [--missions urban_search ...]

Each mission runs in fresh processes (the package's bytecode cached, as Python does by
default), at its own fidelity, with its outputs (event log, summary, recording) written into a
temporary folder. Printed, medians of ``--repeat`` processes:

- **load**: ``load_mission``: the mission file, its world built (an imported world's mesh or
  cloud read, an interior's walls made from its places) and the router;
- **run**: ``Simulation(mission, out_dir=...).run()``, outputs included, and the simulated
  seconds it covered (real-time factor);
- **process**: ``astralis run NAME.yaml --out DIR --quiet`` as a whole, imports included;
- the ratio of each process to a process that only imports what ``astralis run`` imports
  and ends as it does (measured in the same run: what no mission can go below).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

PARTS = """
import json, sys, tempfile, time
from pathlib import Path
from astralis_des import Simulation, load_mission
import rerun
t0 = time.perf_counter()
mission = load_mission(Path(sys.argv[1]))
t1 = time.perf_counter()
result = Simulation(mission, out_dir=Path(tempfile.mkdtemp())).run()
t2 = time.perf_counter()
print(json.dumps({"load": t1 - t0, "run": t2 - t1, "simulated": result.end_time}))
"""
IMPORTS = ("import astralis_des.cli, astralis_des.simulation, rerun; "
           "astralis_des.cli.end_process(0)")  # and ends as `astralis` does


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--missions", nargs="*",
                        default=sorted(p.stem for p in (ROOT / "missions").glob("*.yaml")))
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env |= {"PYTHONPYCACHEPREFIX": cache, "PYTHONPATH": str(ROOT)}

        def process(*argv: str) -> tuple[float, str]:
            t0 = time.perf_counter()
            done = subprocess.run([sys.executable, *argv], capture_output=True, text=True,
                                  check=True, cwd=ROOT, env=env)
            return time.perf_counter() - t0, done.stdout

        process("-c", IMPORTS)  # the bytecode written, as a user's first run does
        imports = statistics.median(process("-c", IMPORTS)[0] for _ in range(args.repeat))
        print(f"importing what `astralis run` imports: {imports:.2f} s (median of "
              f"{args.repeat} processes)\n")
        print(f"{'mission':16} {'load s':>7} {'run s':>7} {'simulated s':>11} "
              f"{'real-time':>9} {'process s':>9} {'/ imports':>9}")
        for name in args.missions:
            path = ROOT / "missions" / f"{name}.yaml"
            process("-c", PARTS, str(path))
            parts = [json.loads(process("-c", PARTS, str(path))[1].strip().splitlines()[-1])
                     for _ in range(args.repeat)]
            whole = statistics.median(
                process("-m", "astralis_des.cli", "run", str(path), "--out",
                        str(Path(out) / name), "--quiet")[0] for _ in range(args.repeat))
            load = statistics.median(p["load"] for p in parts)
            run = statistics.median(p["run"] for p in parts)
            simulated = parts[0]["simulated"]
            print(f"{name:16} {load:7.2f} {run:7.2f} {simulated:11.1f} "
                  f"{simulated / run:8.0f}x {whole:9.2f} {whole / imports:8.1f}x")


if __name__ == "__main__":
    main()
