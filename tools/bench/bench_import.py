"""Import benchmark: real and synthetic files to worlds, against issue 38's goals.

    python tools/bench/bench_import.py [--corpus DIR] [--points 20000000] [--skip-meshes]

Each import runs in a fresh process, as ``astralis world import`` does, so that its wall time
includes starting Python and reading the file, and its peak memory (the child's maximum
resident set, from ``wait4``) is its own. Three parts:

- **The corpus** (``data/scans``, PDAL's 66 test files, or ``--corpus DIR``): each file once,
  killed after ``--limit`` seconds. A run is a world (exit 0), a refusal (exit 2 and one
  line on stderr), a traceback (anything else), or a time-out. Goals: no traceback, no
  time-out, every peak under 1 GB, and a world from every file of at least 100 points over an
  extent that holds a 20 m x 20 m square (measured by reading the file; a file that is
  refused as truncated is bad input, and ``--partial`` is its way in).
- **A synthetic LAZ** of ``--points`` points (20 million: a town of 600 m x 500 m), made by
  this script and not timed: imported in <= 60 s and <= 1.5 GB, printed beside the time laspy
  takes merely to read it, in the same run.
- **autzen_trim.laz**: no slower than 2 s (the whole process); and two meshes.
- **An indoor cloud** of ``--indoor-points`` points (5 million: building A of the default
  world, three storeys sampled on its faces as a scan from inside sees them, with furniture),
  written as LAZ, imported with ``--indoor`` (issue 42): <= 60 s and <= 2 GB, every room of
  the building found, printed beside the time laspy takes to read it.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

AUTZEN = ROOT / "data" / "real" / "autzen_trim.laz"
CORPUS = ROOT / "data" / "scans"
SUFFIXES = (".las", ".laz", ".pcd", ".ply", ".xyz", ".csv", ".obj", ".stl", ".glb", ".gltf")
CLI = "from astralis_des.cli import entry; entry()"  # the `astralis` program
READ_ONLY = """
import sys, time, laspy, numpy as np
t0 = time.perf_counter()
with laspy.open(sys.argv[1]) as f:
    for chunk in f.chunk_iterator(1_000_000):
        np.asarray(chunk.x); np.asarray(chunk.y); np.asarray(chunk.z)
print(time.perf_counter() - t0)
"""
EXTENT = """
import json, sys
from pathlib import Path
from astralis_des.importers.source import Cloud, ReadRequest, check_file, extension, lookup
from astralis_des.importers.survey import survey
path = Path(sys.argv[1])
try:
    check_file(path, extension(path))
    data = lookup(path, extension(path))(path, ReadRequest())
    if isinstance(data, Cloud):
        found = survey(data, "auto", None, 1.0, False)
        print(json.dumps({"points": found.kept, "extent": list(found.hi[:2] - found.lo[:2])}))
    else:
        span = data.vertices.max(axis=0) - data.vertices.min(axis=0)
        print(json.dumps({"points": len(data.vertices), "extent": list(span[:2])}))
except Exception as exc:
    print(json.dumps({"refused": str(exc)}))
"""


@dataclass
class Run:
    code: int | None  # None: killed after the limit
    seconds: float
    peak_gb: float
    out: str
    err: str

    @property
    def outcome(self) -> str:
        if self.code is None:
            return "time-out"
        if self.code == 0:
            return "world"
        if self.code == 2 and len(self.err.strip().splitlines()) == 1 and \
                "Traceback" not in self.err:
            return "refused"
        return "traceback"


def run(args: list[str], limit: float) -> Run:
    """``args`` in a child of its own session; its exit, wall time and peak memory."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        child = subprocess.Popen(args, stdout=out, stderr=err, cwd=ROOT,
                                 start_new_session=True)
        code: int | None = None
        while True:
            pid, status, usage = os.wait4(child.pid, os.WNOHANG)
            if pid:
                code = os.waitstatus_to_exitcode(status)
                break
            if time.perf_counter() - t0 > limit:
                os.killpg(child.pid, signal.SIGKILL)
                _, _, usage = os.wait4(child.pid, 0)
                break
            time.sleep(0.02)
        seconds = time.perf_counter() - t0
        child.returncode = code if code is not None else -9  # reaped by wait4
        out.seek(0)
        err.seek(0)
        return Run(code, seconds, usage.ru_maxrss * 1024 / 1e9,
                   out.read().decode("utf-8", "replace"), err.read().decode("utf-8", "replace"))


def import_args(source: Path, out: Path, *options: str) -> list[str]:
    return [sys.executable, "-c", CLI, "world", "import", str(source), "-o", str(out), *options]


def corpus(folder: Path, limit: float) -> None:
    files = sorted(p for p in folder.rglob("*") if p.suffix.lower() in SUFFIXES)
    print(f"\n## The corpus: {len(files)} files under {folder} ({limit:g} s limit each)\n")
    print("| file | outcome | s | peak GB | points | extent (m) | line |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    tally: dict[str, int] = {}
    missed, slow, heavy = [], [], []
    t_all = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench-corpus-") as tmp:
        for n, path in enumerate(files):
            result = run(import_args(path, Path(tmp) / f"w{n}" / "w.yaml"), limit)
            size = _measure(path)
            eligible = size.get("points", 0) >= 100 and \
                min(size.get("extent", (0, 0))) >= 20.0
            tally[result.outcome] = tally.get(result.outcome, 0) + 1
            if eligible and result.outcome != "world":
                missed.append(path.name)
            if result.seconds > limit or result.code is None:
                slow.append(path.name)
            if result.peak_gb >= 1.0:
                heavy.append(path.name)
            line = (result.err.strip().splitlines() or [""])[-1] if result.outcome != "world" \
                else ""
            extent = " x ".join(f"{v:,.0f}" for v in size["extent"]) if "extent" in size \
                else "-"
            print(f"| {path.relative_to(folder)} | {result.outcome} | {result.seconds:.1f} | "
                  f"{result.peak_gb:.2f} | {size.get('points', '-')} | {extent} | "
                  f"{line[:110].replace('|', '/')} |", flush=True)
    print(f"\n{len(files)} files in {time.perf_counter() - t_all:.0f} s: " +
          ", ".join(f"{k} {v}" for k, v in sorted(tally.items())))
    verdict = [("tracebacks", tally.get("traceback", 0), 0),
               (f"runs past {limit:g} s", len(slow), 0), ("peaks of 1 GB or more", len(heavy), 0),
               ("files of >= 100 points over >= 20 m x 20 m that are not worlds", len(missed), 0)]
    for what, count, goal in verdict:
        print(f"- {what}: {count} (goal {goal}): {'ok' if count <= goal else 'MISSED'}"
              + (f" {missed}" if what.startswith("files") and missed else ""))


def _measure(path: Path) -> dict[str, object]:
    """Points and extent (m) of a file, as the importer reads it, or why it cannot."""
    done = subprocess.run([sys.executable, "-c", EXTENT, str(path)], capture_output=True,
                          text=True, cwd=ROOT, check=False, timeout=120)
    try:
        found: dict[str, object] = json.loads(done.stdout.strip().splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        return {}
    return found


def synthetic(points: int, limit: float) -> None:
    print(f"\n## A synthetic LAZ of {points:,} points\n")
    with tempfile.TemporaryDirectory(prefix="bench-import-") as tmp:
        laz = Path(tmp) / "town.laz"
        t0 = time.perf_counter()
        subprocess.run([sys.executable, __file__, "--make", str(laz), "--points", str(points)],
                       check=True, cwd=ROOT)
        print(f"(made a {laz.stat().st_size / 1e6:,.0f} MB LAZ in "
              f"{time.perf_counter() - t0:.1f} s, not counted)")
        read = run([sys.executable, "-c", READ_ONLY, str(laz)], limit)
        reading = float(read.out.strip() or "nan")
        result = run(import_args(laz, Path(tmp) / "w" / "town.yaml"), limit)
        ok = result.outcome == "world" and result.seconds <= 60 and result.peak_gb <= 1.5
        print(f"- laspy reads it (chunks of 1 M, x, y, z as float64): {reading:.1f} s in its "
              f"process ({read.seconds:.1f} s with start-up), peak {read.peak_gb:.2f} GB")
        print(f"- astralis world import: {result.seconds:.1f} s, peak {result.peak_gb:.2f} GB, "
              f"{result.seconds / read.seconds:.1f}x the read's process; goal <= 60 s and "
              f"<= 1.5 GB: {'ok' if ok else 'MISSED'} ({result.outcome})")
        print("  " + " ".join(result.out.split())[:300])


def indoor(points: int, limit: float) -> None:
    print(f"\n## An indoor LAZ of {points:,} points (--indoor)\n")
    with tempfile.TemporaryDirectory(prefix="bench-import-") as tmp:
        laz = Path(tmp) / "building_a.laz"
        t0 = time.perf_counter()
        subprocess.run([sys.executable, __file__, "--make-indoor", str(laz), "--indoor-points",
                        str(points)], check=True, cwd=ROOT)
        print(f"(made a {laz.stat().st_size / 1e6:,.0f} MB LAZ in "
              f"{time.perf_counter() - t0:.1f} s, not counted)")
        read = run([sys.executable, "-c", READ_ONLY, str(laz)], limit)
        result = run(import_args(laz, Path(tmp) / "w" / "a.yaml", "--indoor"), limit)
        said = " ".join(result.out.split())
        rooms = said.split(" rooms,")[0].rsplit(" ", 1)[-1] if " rooms," in said else "?"
        ok = result.outcome == "world" and result.seconds <= 60 and result.peak_gb <= 2.0 \
            and rooms == "18"
        print(f"- laspy reads it: {read.seconds:.1f} s with start-up, peak {read.peak_gb:.2f} GB")
        print(f"- astralis world import --indoor: {result.seconds:.1f} s, peak "
              f"{result.peak_gb:.2f} GB, {result.seconds / read.seconds:.1f}x the read's "
              f"process; {rooms} rooms of 18; goal <= 60 s, <= 2 GB, 18 rooms: "
              f"{'ok' if ok else 'MISSED'} ({result.outcome})")
        print("  " + said[:300])


def indoor_cloud(path: Path, points: int) -> None:
    """Building A of the default world sampled on its faces (tests/indoor_scenes.py), about
    ``points`` points, as LAZ."""
    import laspy

    sys.path.insert(0, str(ROOT / "tests"))
    from indoor_scenes import building_a, face_cloud

    scene = building_a()
    probe = len(face_cloud(scene, 0.1))
    cloud = face_cloud(scene, 0.1 * math.sqrt(probe / points), seed=1)
    header = laspy.LasHeader(point_format=0, version="1.2")
    header.scales, header.offsets = [0.001, 0.001, 0.001], [0.0, 0.0, 0.0]
    las = laspy.LasData(header)
    las.x, las.y, las.z = cloud[:, 0], cloud[:, 1], cloud[:, 2]
    las.write(path)


def reference(skip_meshes: bool, limit: float) -> None:
    print("\n## Reference files\n")
    with tempfile.TemporaryDirectory(prefix="bench-import-") as tmp:
        cases = [("autzen_trim.laz", AUTZEN, ()), ("autzen_trim.laz --voxel 0.2", AUTZEN,
                                                   ("--voxel", "0.2"))]
        if not skip_meshes:
            import pybullet_data

            meshes = Path(pybullet_data.getDataPath())
            cases += [("bunny.obj", meshes / "bunny.obj", ("--margin", "10", "--area-size", "8")),
                      ("samurai_monastry.obj --voxel 0.5", meshes / "samurai_monastry.obj",
                       ("--voxel", "0.5", "--area-size", "10"))]
        for n, (name, source, options) in enumerate(cases):
            result = run(import_args(source, Path(tmp) / f"r{n}" / "w.yaml", *options), limit)
            goal = ""
            if name == "autzen_trim.laz":
                goal = f"; goal <= 2 s: {'ok' if result.seconds <= 2.0 else 'MISSED'}"
            print(f"- {name}: {result.seconds:.2f} s (whole process), peak "
                  f"{result.peak_gb:.2f} GB, {result.outcome}{goal}")


def synthetic_cloud(path: Path, points: int, seed: int = 0) -> None:
    """A 600 m x 500 m town on a gentle slope: ground (half the points, 2 cm of noise), 40
    flat-roofed buildings (walls and roofs) and 300 trees, unclassified, written as LAZ."""
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--corpus", type=Path, default=CORPUS, help="folder of files to "
                        "import, each in its own process (default: data/scans)")
    parser.add_argument("--limit", type=float, default=30.0, help="s a corpus file may take")
    parser.add_argument("--points", type=int, default=20_000_000)
    parser.add_argument("--skip-corpus", action="store_true")
    parser.add_argument("--skip-synthetic", action="store_true")
    parser.add_argument("--skip-meshes", action="store_true")
    parser.add_argument("--indoor-points", type=int, default=5_000_000)
    parser.add_argument("--skip-indoor", action="store_true")
    parser.add_argument("--make", help=argparse.SUPPRESS)  # write the synthetic cloud only
    parser.add_argument("--make-indoor", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.make:
        synthetic_cloud(Path(args.make), args.points)
        return
    if args.make_indoor:
        indoor_cloud(Path(args.make_indoor), args.indoor_points)
        return
    print(f"# Import benchmark ({os.cpu_count()} cores; every import a fresh process)")
    reference(args.skip_meshes, 120.0)
    if not args.skip_corpus:
        corpus(args.corpus, args.limit)
    if not args.skip_indoor:
        indoor(args.indoor_points, 600.0)
    if not args.skip_synthetic:
        synthetic(args.points, max(600.0, math.ceil(args.points / 1e5)))


if __name__ == "__main__":
    main()
