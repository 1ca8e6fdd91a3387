"""Container benchmark: the image's size, and the wall time of the default mission inside the
container against the same run outside it.

    python tools/bench/bench_container.py [--image astralis-des] [--repeat 3] [--warmup 1]

Build the image first (this machine's podman needs the runc runtime and the host network):

    podman --runtime runc build --network host -v /etc/ssl/certs:/hostcerts:ro \\
        --build-arg BASE=localhost/debian-bookworm -t astralis-des .

Inside: ``podman run --rm ... IMAGE run missions/urban_search.yaml --out /out/x``, timed as a
whole process (container start and stop included), its outputs on a mounted folder. Outside:
``astralis run missions/urban_search.yaml --out X`` as a subprocess of the environment running
this script. Median of ``--repeat`` runs each, after ``--warmup`` runs each that are not
counted. Goal: inside within 1.5x of outside.
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PODMAN = ["podman", "--runtime", "runc"]
MISSION = "missions/urban_search.yaml"
GOAL = 1.5


def astralis() -> list[str]:
    exe = Path(sys.executable).with_name("astralis")
    if exe.is_file():
        return [str(exe)]
    return [sys.executable, "-c", "from astralis_des.cli import entry; entry()"]


def timed(cmd: list[str], cwd: Path) -> float:
    start = time.perf_counter()
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=300,
                          check=False)
    elapsed = time.perf_counter() - start
    if proc.returncode != 0:
        sys.exit(f"failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stdout}{proc.stderr}")
    return elapsed


def image_size(image: str) -> int:
    proc = subprocess.run([*PODMAN, "image", "inspect", "--format", "{{.Size}}", image],
                          capture_output=True, text=True, timeout=60, check=False)
    if proc.returncode != 0:
        sys.exit(f"no image {image}: build it first (see this script's docstring)\n"
                 f"{proc.stderr.strip()}")
    return int(proc.stdout.strip())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--image", default="astralis-des")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--warmup", type=int, default=1)
    args = parser.parse_args()
    if shutil.which("podman") is None:
        sys.exit("podman is not installed")

    size = image_size(args.image)
    print(f"image {args.image}: {size:,} bytes ({size / 1e9:.2f} GB)")

    with tempfile.TemporaryDirectory(prefix="bench_container_") as tmp:
        mount = Path(tmp)
        inside_cmd = [*PODMAN, "run", "--rm", "--network", "host", "-v", f"{mount}:/out",
                      args.image, "run", MISSION, "--out", "/out/x"]
        outside_cmd = [*astralis(), "run", MISSION, "--out", str(mount / "host")]
        inside: list[float] = []
        outside: list[float] = []
        for k in range(args.warmup + args.repeat):
            t_in, t_out = timed(inside_cmd, ROOT), timed(outside_cmd, ROOT)  # interleaved
            if k >= args.warmup:
                inside.append(t_in)
                outside.append(t_out)
        same = (mount / "x" / "events.jsonl").read_bytes() == \
            (mount / "host" / "events.jsonl").read_bytes()

    med_in, med_out = statistics.median(inside), statistics.median(outside)
    ratio = med_in / med_out
    print(f"default mission ({MISSION}), whole process, median of {args.repeat} "
          f"(after {args.warmup} warm-up):")
    print(f"  inside  the container: {med_in:6.2f} s   runs: "
          + ", ".join(f"{t:.2f}" for t in inside))
    print(f"  outside              : {med_out:6.2f} s   runs: "
          + ", ".join(f"{t:.2f}" for t in outside))
    print(f"  ratio inside/outside : {ratio:6.2f}x   goal <= {GOAL}x: "
          + ("met" if ratio <= GOAL else "NOT met"))
    print(f"  event logs identical : {'yes' if same else 'NO'}")
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
