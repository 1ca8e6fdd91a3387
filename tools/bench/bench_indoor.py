"""Indoor analysis benchmark: storeys, rooms and doors of building clouds (issue 42).

    python tools/bench/bench_indoor.py [--points 5000000] [--cap-gb 4]

Clouds are sampled on the faces of generated buildings (``tests/indoor_scenes.py``: walls,
slabs and furniture where a scan from inside sees them, 1 cm of noise, 15% dropped) and
written by this script first, untimed:

- **A 0.29M**: building A of the default world at the tests' density (one point per 0.1 m
  square of face);
- **A 5M**: the same building at ``--points`` points (about one per 2.4 cm square);
- **B1 5M**: a building of 500 rooms (5 storeys of 4 segments of 25 rooms, 208 m x 16.5 m,
  ``tests/bigworld.py``) at ``--points`` points.

Writing the clouds takes two to three minutes. Each runs ``find_interior`` (cells of 0.05 m,
the default) in a fresh process, so that its time and its peak memory (the child's
``VmHWM``, Python, numpy and the cloud included; ``ru_maxrss`` would carry this script's peak
over into the child) are its own; ``baseline`` is a child that only imports the package and
loads the 5M cloud.
The child's address space is capped (``--cap-gb``). Scores against the truth: rooms matched
(IoU >= 0.8), the least IoU, doors found (centre within 0.3 m, width within 0.2 m), the
worst centre and width errors, false rooms over 4 m². The goal: a 5-million-point cloud in
<= 60 s and <= 2 GB. Ratios: each cloud's time per million points, and peak memory over the
baseline's.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from bigworld import write_big_world  # noqa: E402
from indoor_scenes import building_a, face_cloud, world_building  # noqa: E402

CHILD = """
import json, resource, sys, time
sys.path.insert(0, {tests!r})
cap = int(float(sys.argv[3]) * 2**30)
resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
import numpy as np
from astralis_des.importers.indoor import find_interior
points = np.load(sys.argv[1])
out = {{"points": len(points)}}
if sys.argv[2] != "baseline":
    from indoor_scenes import building_a, score, world_building
    from pathlib import Path
    t0 = time.perf_counter()
    interior = find_interior(points)
    out["seconds"] = time.perf_counter() - t0
    name, _, world = sys.argv[2].partition("@")
    scene = building_a() if name == "A" else world_building(Path(world), name)
    s = score(scene, interior)
    errors = list(s.door_error.values())
    out.update(storeys=[[st.z, st.height] for st in interior.storeys],
               rooms=len(scene.rooms), matched=sum(v >= 0.8 for v in s.iou.values()),
               min_iou=min(s.iou.values()), doors=len(errors),
               doors_ok=sum(c <= 0.3 and w <= 0.2 and ok for c, w, ok in errors),
               worst_centre=max(c for c, _, _ in errors),
               worst_width=max(w for _, w, _ in errors),
               false_rooms=len(s.false_rooms), extra_doors=s.extra_doors,
               found_rooms=len(interior.rooms))
# VmHWM, not ru_maxrss: Linux carries the parent's peak over into ru_maxrss across exec
status = open("/proc/self/status").read().split("VmHWM:")[1].split()
out["peak_gb"] = int(status[0]) / 2**20
print(json.dumps(out))
"""


def spacing_for(scene_points: int, at: float, want: int) -> float:
    """The face spacing that gives about ``want`` points, from ``scene_points`` at ``at``."""
    return at * math.sqrt(scene_points / want)


def child(cloud: Path, name: str, cap_gb: float) -> dict[str, object]:
    code = CHILD.format(tests=str(ROOT / "tests"))
    done = subprocess.run([sys.executable, "-c", code, str(cloud), name, str(cap_gb)],
                          capture_output=True, text=True, cwd=ROOT, check=False,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    if done.returncode:
        return {"error": done.stderr.strip().splitlines()[-1]}
    result: dict[str, object] = json.loads(done.stdout)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--points", type=int, default=5_000_000)
    parser.add_argument("--cap-gb", type=float, default=4.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        big = write_big_world(folder / "big.yaml", 500)
        t0 = time.perf_counter()
        a = building_a()
        sparse = face_cloud(a, 0.1)
        dense = face_cloud(a, spacing_for(len(sparse), 0.1, args.points), seed=1)
        b1 = world_building(big, "B1")
        probe = face_cloud(b1, 0.3)
        b1_dense = face_cloud(b1, spacing_for(len(probe), 0.3, args.points), seed=2)
        jobs = [("A 0.29M", "A", sparse), ("A 5M", "A", dense), ("B1 5M", f"B1@{big}", b1_dense)]
        print(f"clouds written in {time.perf_counter() - t0:.0f} s (untimed)")
        results = {}
        for label, name, points in jobs:
            path = folder / f"{label.replace(' ', '_')}.npy"
            np.save(path, points.astype(np.float64))
            results[label] = child(path, name, args.cap_gb)
        results["baseline"] = child(folder / "A_5M.npy", "baseline", args.cap_gb)
    base = results["baseline"]
    print(f"{'cloud':10} {'points':>10} {'s':>7} {'s/Mpt':>6} {'peak GB':>8} {'x base':>7} "
          f"{'rooms':>7} {'min IoU':>8} {'doors':>7} {'centre':>7} {'width':>6} "
          f"{'false':>5} {'extra':>5}")
    for label, r in results.items():
        if "error" in r:
            print(f"{label:10} {r['error']}")
            continue
        if label == "baseline":
            print(f"{label:10} {r['points']:>10,} {'':>7} {'':>6} {r['peak_gb']:>8.2f}")
            continue
        print(f"{label:10} {r['points']:>10,} {r['seconds']:>7.1f} "
              f"{r['seconds'] / r['points'] * 1e6:>6.2f} {r['peak_gb']:>8.2f} "
              f"{r['peak_gb'] / base['peak_gb']:>7.1f} "
              f"{r['matched']:>3}/{r['rooms']:<3} {r['min_iou']:>8.3f} "
              f"{r['doors_ok']:>3}/{r['doors']:<3} {r['worst_centre']:>7.3f} "
              f"{r['worst_width']:>6.3f} {r['false_rooms']:>5} {r['extra_doors']:>5}")
        print(f"{'':10} storeys (z, height): {r['storeys']}")
    print("goal for 5M points: <= 60 s, <= 2 GB")


if __name__ == "__main__":
    main()
