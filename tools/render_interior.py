"""Draw a world's interior over what it was imported from, a storey at a time: each place
filled by its kind and labelled with its id, each door a red bar across its gap, stairs as
arrows, over the world's cloud (its points between knee and head height of the storey, dark)
or its mesh (upright triangles). What a person checks before correcting a world file.

    python tools/render_interior.py worlds/hospital.yaml -o docs/interior_hospital.png
    python tools/render_interior.py twin.yaml --storey 2 -o storey2.png
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import yaml
from matplotlib.collections import PolyCollection
from matplotlib.patches import Polygon

from astralis_des.world.build import load_world

KNEE, HEAD = 0.5, 1.8  # m over the storey's floor: the slice of the cloud drawn
COLOURS = {"room": "tab:blue", "hall": "tab:cyan", "corridor": "0.75", "stairwell": "tab:olive"}


def render(world_file: Path, out: Path, storey: int, title: str | None) -> None:
    world = load_world(world_file)
    doc = yaml.safe_load(world_file.read_text(encoding="utf-8"))
    section = doc.get("interior")
    if world.interior is None or section is None:
        raise SystemExit(f"{world_file}: no interior (import with --indoor)")
    z = world.interior.storeys[storey - 1]
    height = section["storeys"][storey - 1]["height"]
    fig, ax = plt.subplots(figsize=(8.0, 8.0))
    imported = world.imported
    if imported is not None and imported.cloud is not None:
        pts = imported.cloud
        band = (pts[:, 2] >= z + KNEE) & (pts[:, 2] <= z + HEAD)
        ax.scatter(pts[band, 0], pts[band, 1], s=0.3, c="0.1", lw=0, zorder=3)
    elif imported is not None and imported.vertices is not None and imported.faces is not None:
        tri = imported.vertices[imported.faces]
        upright = (np.ptp(tri[:, :, 2], axis=1) > 0.3) & (tri[:, :, 2].min(axis=1) < z + HEAD) \
            & (tri[:, :, 2].max(axis=1) > z + KNEE)
        ax.add_collection(PolyCollection(tri[upright][:, :, :2], facecolor="0.1",
                                         edgecolor="0.1", lw=0.4, zorder=3))
    for place in section["places"]:
        if int(place["id"].split(".")[1]) != storey:
            continue
        xy = np.array(place["outline"])
        ax.add_patch(Polygon(xy, closed=True, facecolor=COLOURS[place["kind"]], alpha=0.45,
                             lw=0.6, edgecolor="k", zorder=2))
        seat = world.interior.seats[place["id"]]
        ax.text(seat[0], seat[1], place["id"].split(".", 2)[2], ha="center", va="center",
                fontsize=7, zorder=4)
    for door in section["doors"]:
        if not any(p.split(".")[1] == str(storey) for p in door["between"] if "." in p):
            continue
        (x, y), half = door["at"], door["width"] / 2
        dx, dy = (0.0, half) if door["across"] == "x" else (half, 0.0)
        ax.plot([x - dx, x + dx], [y - dy, y + dy], color="red", lw=2.5, zorder=5)
    for stair in section.get("stairs", []):
        levels = [int(p.split(".")[1]) for p in stair["between"]]
        if storey in levels:
            a, b = (world.interior.seats[p] for p in stair["between"])
            ax.annotate("", xy=b[:2], xytext=a[:2], zorder=5,
                        arrowprops={"arrowstyle": "->", "color": "tab:green", "lw": 1.5})
    fp = world.interior.footprint
    ax.set_xlim(fp.lo[0] - 1, fp.hi[0] + 1)
    ax.set_ylim(fp.lo[1] - 1, fp.hi[1] + 1)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title or f"{world.name}: storey {storey} (floor at {z:g} m, {height:g} m "
                 "high); rooms blue, halls cyan, corridors grey, stairwells olive, doors "
                 "red, stairs green", fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=150)
    print(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("world", type=Path)
    parser.add_argument("-o", "--out", type=Path, required=True)
    parser.add_argument("--storey", type=int, default=1)
    parser.add_argument("--title")
    args = parser.parse_args()
    render(args.world, args.out, args.storey, args.title)


if __name__ == "__main__":
    main()
