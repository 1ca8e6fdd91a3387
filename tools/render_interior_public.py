"""Draw docs/interior_public.png: the rooms and doors ``find_interior`` finds in the AWS
RoboMaker hospital's first floor (tests/data/interiors/aws_hospital), over the model's top
view, with the plan's true rooms outlined.

    PYTHONPATH=. python tools/render_interior_public.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.patches import Polygon, Rectangle

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from interior_models import INTERIORS, load_obj, load_plan, sample_faces  # noqa: E402

from astralis_des.importers.indoor import find_interior  # noqa: E402


def main(out: Path = ROOT / "docs" / "interior_public.png") -> None:
    vertices, parts = load_obj(INTERIORS / "aws_hospital" / "hospital_floor1.obj")
    interior = find_interior(sample_faces(vertices, np.concatenate(list(parts.values())), 0.05))
    plan = load_plan("aws_hospital")
    fig, ax = plt.subplots(figsize=(6.0, 12.0))
    cmap = plt.get_cmap("tab20")
    for k, room in enumerate(interior.rooms):
        xy = interior.to_cloud(np.array(room.polygon))
        ax.add_patch(Polygon(xy, closed=True, facecolor=cmap(k % 20), alpha=0.55, lw=0))
        cx, cy = interior.to_cloud(np.array([room.centre]))[0]
        ax.text(cx, cy, room.id, ha="center", va="center", fontsize=6)
    walls = [name for name in parts if name not in ("floor_01_floor", "floor_01_ceiling")]
    tri = vertices[np.concatenate([parts[n] for n in walls])]
    upright = np.ptp(tri[:, :, 2], axis=1) > 0.3
    ax.add_collection(PolyCollection(tri[upright][:, :, :2], facecolor="0.15",
                                     edgecolor="0.15", lw=0.3))
    for room in plan["rooms"]:
        for x0, y0, x1, y1 in room["rects"]:
            ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ls="--", lw=0.4,
                                   ec="navy"))
    for door in interior.doors:
        x, y = interior.to_cloud(np.array([door.centre]))[0]
        half = door.width / 2
        along = np.array([0.0, half]) if door.normal_axis == 0 else np.array([half, 0.0])
        ax.plot([x - along[0], x + along[0]], [y - along[1], y + along[1]], color="red", lw=2)
    for door in plan["doors"]:
        ax.plot(*door["centre"], "x", color="navy", ms=3)
    ax.set_xlim(-13.5, 13.5)
    ax.set_ylim(-36, 22)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("AWS RoboMaker hospital, floor 1: found rooms (colour, id), doors (red);\n"
                 "plan's rooms dashed, its doors x", fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=170)


if __name__ == "__main__":
    main()
