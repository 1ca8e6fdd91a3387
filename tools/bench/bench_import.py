"""Import benchmark: real and synthetic files to worlds, against the issue's goals.

    python tools/bench/bench_import.py [--points 5000000] [--skip-meshes]

Each import runs in a fresh process, so that its wall time includes reading the file and its
peak memory (the process's maximum resident set, ``ru_maxrss``) is its own (it counts from
the small parent's at the fork, about 0.1 GB). Prints, per case,
the wall time, the peak memory, and what the world holds. Goals: autzen_trim.laz under 3 s;
a synthetic 5-million-point cloud under 30 s and 2 GB.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

AUTZEN = ROOT / "data" / "real" / "autzen_trim.laz"
GOALS = {"autzen_trim.laz": (3.0, None), "synthetic": (30.0, 2.0)}  # s, GB

# Runs in the child: import, then report time and peak memory as one JSON line.
CHILD = """
import json, resource, sys, time
t0 = time.perf_counter()
from astralis_des.importers import ImportOptions, import_world
options = ImportOptions(**json.loads(sys.argv[3]))
report = import_world(sys.argv[1], sys.argv[2], options)
seconds = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"seconds": seconds, "peak": peak, "points": report.points,
                  "blocks": report.blocks, "areas": len(report.areas),
                  "ground": report.ground, "share": report.ground_share,
                  "site": report.site}))
"""
BASELINE = """
import json, resource
import laspy, numpy, scipy, trimesh
from astralis_des.importers import import_world
print(json.dumps({"peak": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}))
"""


def run_child(source: Path, out: Path, options: dict[str, object]) -> dict[str, object]:
    wall = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", CHILD, str(source), str(out),
                           json.dumps(options)], capture_output=True, text=True, check=False,
                          cwd=ROOT)
    if done.returncode != 0:
        raise SystemExit(f"import of {source} failed:\n{done.stderr}")
    result: dict[str, object] = json.loads(done.stdout.strip().splitlines()[-1])
    result["process"] = time.perf_counter() - wall
    return result


def synthetic_cloud(path: Path, points: int, seed: int = 0) -> None:
    """A 600 m x 500 m town on a gentle slope: ground (half the points), 40 flat-roofed
    buildings (walls and roofs) and 300 trees, unclassified, written as LAZ."""
    import laspy
    import numpy as np

    rng = np.random.default_rng(seed)
    n_ground = points // 2
    xy = rng.uniform([0, 0], [600, 500], size=(n_ground, 2))
    ground = np.column_stack([xy, 0.01 * xy[:, 0] + rng.normal(0, 0.02, n_ground)])
    n_building = points // 4
    corner = rng.uniform([20, 20], [560, 460], size=(40, 2))
    size = rng.uniform([10, 10], [35, 30], size=(40, 2))
    height = rng.uniform(5, 25, size=40)
    which = rng.integers(0, 40, n_building)
    u = rng.uniform(0, 1, size=(n_building, 2))
    on_roof = rng.uniform(0, 1, n_building) < 0.6
    bxy = corner[which] + u * size[which]
    wall = ~on_roof
    side = rng.integers(0, 4, n_building)
    bxy[wall & (side == 0), 0] = corner[which][wall & (side == 0), 0]
    bxy[wall & (side == 1), 1] = corner[which][wall & (side == 1), 1]
    base = 0.01 * bxy[:, 0]
    bz = np.where(on_roof, base + height[which], base + u[:, 1] * height[which])
    building = np.column_stack([bxy, bz])
    n_tree = points - n_ground - n_building
    centre = rng.uniform([0, 0], [600, 500], size=(300, 2))
    crown = rng.uniform(2, 6, 300)
    tree_h = rng.uniform(6, 18, 300)
    t = rng.integers(0, 300, n_tree)
    offset = rng.normal(0, 1, size=(n_tree, 3)) * crown[t, None] / 2
    tz = 0.01 * centre[t, 0] + tree_h[t] - np.abs(offset[:, 2])
    tree = np.column_stack([centre[t] + offset[:, :2], tz])
    cloud = np.vstack([ground, building, tree])
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.scales, header.offsets = [0.01, 0.01, 0.01], [0.0, 0.0, 0.0]
    las = laspy.LasData(header)
    las.x, las.y, las.z = cloud[:, 0], cloud[:, 1], cloud[:, 2]
    las.write(path)


def line(name: str, result: dict[str, object]) -> str:
    seconds, peak = float(result["seconds"]), float(result["peak"]) / 1e9  # type: ignore[arg-type]
    goal = GOALS.get(name)
    verdict = ""
    if goal is not None:
        ok = seconds < goal[0] and (goal[1] is None or peak < goal[1])
        verdict = f"; goal < {goal[0]:g} s" + (f", < {goal[1]:g} GB" if goal[1] else "") + \
            (": ok" if ok else ": MISSED")
    site = result["site"]
    return (f"{name}: {seconds:.2f} s in the process ({float(result['process']):.2f} s with "  # type: ignore[arg-type]
            f"interpreter start), peak {peak:.2f} GB{verdict}\n"
            f"  {int(result['points']):,} points/faces, {int(result['blocks']):,} blocks, "  # type: ignore[call-overload]
            f"{result['areas']} areas, site {site[0]:g} x {site[1]:g} m"  # type: ignore[index]
            + (f", ground by {result['ground']} {float(result['share']):.1%}"  # type: ignore[arg-type]
               if result["ground"] else ""))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--points", type=int, default=5_000_000)
    parser.add_argument("--skip-meshes", action="store_true")
    parser.add_argument("--make", help=argparse.SUPPRESS)  # write the synthetic cloud only
    args = parser.parse_args()
    if args.make:
        synthetic_cloud(Path(args.make), args.points)
        return
    base = subprocess.run([sys.executable, "-c", BASELINE], capture_output=True, text=True,
                          check=True, cwd=ROOT)
    print(f"interpreter with numpy, scipy, laspy, trimesh loaded: peak "
          f"{json.loads(base.stdout)['peak'] / 1e9:.2f} GB")
    with tempfile.TemporaryDirectory(prefix="bench-import-") as folder:
        out = Path(folder)
        if AUTZEN.is_file():
            for voxel in (0.2, 1.0):
                result = run_child(AUTZEN, out / "autzen.yaml", {"voxel": voxel})
                print(line("autzen_trim.laz", result).replace(
                    "autzen_trim.laz:", f"autzen_trim.laz (voxel {voxel:g} m):", 1))
        else:
            print(f"autzen_trim.laz: not found at {AUTZEN}")
        t0 = time.perf_counter()
        synthetic = out / "synthetic.laz"
        # Made in a child: a fork's ru_maxrss starts at its parent's, so the parent stays small.
        subprocess.run([sys.executable, __file__, "--make", str(synthetic), "--points",
                        str(args.points)], check=True, cwd=ROOT)
        print(f"(made a {args.points:,}-point LAZ of {synthetic.stat().st_size / 1e6:.0f} MB "
              f"in {time.perf_counter() - t0:.1f} s, not counted)")
        for voxel in (0.2, 0.5):
            result = run_child(synthetic, out / "synthetic.yaml", {"voxel": voxel})
            print(line("synthetic", result).replace(
                "synthetic:", f"synthetic {args.points:,} points, LAZ, ground by grid "
                f"(voxel {voxel:g} m):", 1))
        if not args.skip_meshes:
            import pybullet_data

            meshes = Path(pybullet_data.getDataPath())
            print(line("bunny.obj", run_child(meshes / "bunny.obj", out / "bunny.yaml",
                                              {"margin": 10.0, "area_size": 8.0})))
            print(line("samurai_monastry.obj (voxel 0.5 m)",
                       run_child(meshes / "samurai_monastry.obj", out / "monastery.yaml",
                                 {"voxel": 0.5, "area_size": 10.0})))


if __name__ == "__main__":
    main()
