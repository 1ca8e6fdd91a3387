"""``astralis diff`` benchmark: the whole command on two default-mission runs, against a run.

    python tools/bench/bench_diff.py [--repeat 3] [--fidelity kinematic]

Runs the default mission under ``mixed`` and under ``greedy`` with ``astralis run`` (each a
process of its own, as a user runs it), then times, each in a process of its own, ``astralis
diff A B`` (the tables) and ``astralis diff A B -o diff.rrd`` (and the recording), and prints
their wall times, medians of ``--repeat``, with their ratio to the ``astralis run`` of the
mission measured in the same run. Goal (issue 44): the diff under 2 s wall.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MISSION = ROOT / "missions" / "urban_search.yaml"


def timed(*argv: str) -> float:
    """Wall seconds of ``astralis ARGV`` in a process of its own (it must succeed)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "astralis_des.cli", *argv], check=True, env=env,
                   stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--fidelity", default="kinematic")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        greedy = base / "greedy.yaml"
        greedy.write_text(MISSION.read_text(encoding="utf-8")
                          .replace("strategy: mixed", "strategy: greedy")
                          .replace("../worlds/", f"{ROOT / 'worlds'}/"), encoding="utf-8")
        runs = [timed("run", str(MISSION), "-q", "--fidelity", args.fidelity, "-o",
                      str(base / "A")) for _ in range(args.repeat)]
        timed("run", str(greedy), "-q", "--fidelity", args.fidelity, "-o", str(base / "B"))
        table = [timed("diff", str(base / "A"), str(base / "B"))
                 for _ in range(args.repeat)]
        drawn = [timed("diff", str(base / "A"), str(base / "B"), "-o", str(base / "d.rrd"))
                 for _ in range(args.repeat)]
        size = (base / "d.rrd").stat().st_size
    run, tables, both = (statistics.median(x) for x in (runs, table, drawn))
    print(f"default mission, {args.fidelity}, mixed vs greedy (medians of {args.repeat}, "
          f"each command a process of its own):")
    print(f"  astralis run MISSION -o A     {run:6.2f} s")
    print(f"  astralis diff A B             {tables:6.2f} s  ({tables / run:.2f}x the run)")
    print(f"  astralis diff A B -o d.rrd    {both:6.2f} s  ({both / run:.2f}x the run; "
          f"goal 2 s: {'met' if both < 2.0 else 'NOT met'}); d.rrd {size / 1e6:.2f} MB")


if __name__ == "__main__":
    main()
