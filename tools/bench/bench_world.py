"""World-scale benchmark: worlds of 1,000 to 10,000 rooms and a 100,000-event timeline.

    python tools/bench/bench_world.py [--rooms 1000 2000 10000] [--events 100000] [--cap-gb 8]

Each measurement runs in a fresh process, so its peak memory (``ru_maxrss`` of the child) is
its own; the files are written by this script first and not timed (``tests/bigworld.py``:
buildings of 5 storeys of 4 segments of 25 rooms, in a grid). For each size:

- **load**: reading, validating and building the world and its router (``world.router``);
- **route**: one route from the open ground to a room on the top storey of the farthest
  building, for a person, then a second one from a room of the first building (its
  distances computed when asked) and the first again (from the cache);
- **peak**: the process's maximum resident set, Python and its imports included (about
  0.2 GB of it).

The goal (issue 39): the documented 10,000 rooms load and answer in <= 30 s and <= 2 GB. The
child's address space is capped (``--cap-gb``) so that a build that would not fit ends in a
``MemoryError`` rather than in the OOM killer. Then ``astralis validate`` of a mission with a
100,000-event timeline, the whole process: the goal is <= 10 s.

Ratios measured in the same run: each size's load against the 1,000-room world's (how it
scales), and ``validate`` against libyaml alone loading the same file
(``yaml.load(..., CSafeLoader)`` in a fresh process: what no checking can go below).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from bigworld import write_big_world, write_timeline_mission  # noqa: E402

CHILD = """
import json, resource, sys, time
t0 = time.perf_counter()
from astralis_des.world.build import read_world
from pathlib import Path
t1 = time.perf_counter()
world = read_world(Path(sys.argv[1]))
router = world.router
t2 = time.perf_counter()
last = sorted(world.buildings)[-1]
far = max((r for r in world.rooms.values() if r.building == last), key=lambda r: r.floor)
first = next(iter(world.rooms.values()))
way = router.route((1.0, 1.0, 0.0), far.center, "human")
t3 = time.perf_counter()
router.route(first.center, far.center, "human")
t4 = time.perf_counter()
router.route((1.0, 1.0, 0.0), far.center, "human")
t5 = time.perf_counter()
print(json.dumps({"imports": t1 - t0, "load": t2 - t1, "route": t3 - t2, "route2": t4 - t3,
                  "cached": t5 - t4, "legs": len(way) - 1,
                  "peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6}))
"""


def _capped(gb: float) -> None:
    limit = int(gb * 1e9)
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def _child(argv: list[str], cap_gb: float) -> tuple[int, str, str, float, float]:
    """Run ``argv`` in a fresh process: its exit code, output, errors, wall time and peak
    resident set in GB (its own, from ``wait4``)."""
    start = time.perf_counter()
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        child = subprocess.Popen(argv, stdout=out, stderr=err, cwd=ROOT, text=True,
                                 preexec_fn=lambda: _capped(cap_gb))
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)
        wall = time.perf_counter() - start
        out.seek(0)
        err.seek(0)
        return child.returncode, out.read(), err.read(), wall, usage.ru_maxrss / 1e6


def world_size(path: Path, cap_gb: float) -> dict[str, object]:
    code, out, err, wall, _ = _child([sys.executable, "-c", CHILD, str(path)], cap_gb)
    if code != 0:
        last = (err.strip().splitlines() or ["?"])[-1]
        return {"failed": f"exit {code}: {last[:120]}", "wall": wall}
    return {**json.loads(out), "wall": wall}


def validate_time(mission: Path, cap_gb: float) -> dict[str, object]:
    code, out, err, wall, peak = _child(
        [sys.executable, "-m", "astralis_des.cli", "validate", str(mission)], cap_gb)
    said = (out + err).strip().splitlines()
    return {"exit": code, "wall": wall, "peak_gb": peak, "said": said[-1][:140] if said else ""}


YAML_ONLY = """
import sys, time, yaml
t0 = time.perf_counter()
yaml.load(open(sys.argv[1], encoding="utf-8"), Loader=yaml.CSafeLoader)
print(time.perf_counter() - t0)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rooms", type=int, nargs="*", default=[1000, 2000, 10000])
    parser.add_argument("--events", type=int, default=100_000)
    parser.add_argument("--cap-gb", type=float, default=8.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        print("rooms   load s  route s  2nd route s  cached s  peak GB  process s  load / first")
        first_load = None
        for rooms in args.rooms:
            path = write_big_world(folder / f"big_{rooms}.yaml", rooms)
            got = world_size(path, args.cap_gb)
            if "failed" in got:
                print(f"{rooms:>6,}  {got['failed']} (after {got['wall']:.1f} s)")
                continue
            load = float(got["load"])  # type: ignore[arg-type]
            first_load = first_load or load
            print(f"{rooms:>6,}  {load:6.2f}  {got['route']:7.3f}  {got['route2']:11.3f}"
                  f"  {got['cached']:8.4f}  {got['peak_gb']:7.2f}  {got['wall']:9.2f}"
                  f"  {load / first_load:11.1f}x")
        if args.events:
            mission = write_timeline_mission(folder / "timeline.yaml",
                                             ROOT / "worlds" / "urban_default.yaml", args.events)
            got = validate_time(mission, args.cap_gb)
            code, out, _, _, _ = _child([sys.executable, "-c", YAML_ONLY, str(mission)],
                                        args.cap_gb)
            yaml_only = float(out) if code == 0 else float("nan")
            wall = float(got["wall"])  # type: ignore[arg-type]
            print(f"astralis validate, {args.events:,} timeline events: {wall:.1f} s, "
                  f"peak {got['peak_gb']:.2f} GB, exit {got['exit']}: {got['said']}")
            print(f"libyaml alone loading it: {yaml_only:.1f} s; validate / libyaml: "
                  f"{wall / yaml_only:.1f}x")


if __name__ == "__main__":
    main()
