"""Draws the path each UAV search pattern of Table I flies in one room of the default world:
``docs/patterns.png`` (the README's figure).

    python tools/pattern_figure.py [--room A.1.1.2] [--out docs/patterns.png]

Each pattern is run as a task by a UAV of the default mission (kinematic fidelity, the room
left empty); the figure draws the path the UAV planned for the search, from the first point
(a circle) to the last (a cross), over the room's walls and door.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from astralis_des import Simulation, load_mission  # noqa: E402

PATTERNS = ("spiral_inward", "spiral_outward", "sweep_horizontal", "sweep_vertical")


def pattern_path(room: str, action: str) -> np.ndarray:
    """The path a UAV plans for ``action`` in ``room``: its last planned leg's points."""
    mission = load_mission(ROOT / "missions" / "urban_search.yaml").with_changes(
        assignment={"auto": False}, scene={"clutter": False})
    sim = Simulation(mission)
    sim.start()
    done = sim.enqueue("uav1", action, room)
    sim.advance(600.0)
    assert done.triggered and done.value.ok, done.value.message if done.triggered else action
    path = sim.robots["uav1"].plans[-1][1]
    sim.finish()
    return np.asarray(path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--room", default="A.1.1.2")
    parser.add_argument("--out", default=str(ROOT / "docs" / "patterns.png"))
    args = parser.parse_args()
    world = load_mission(ROOT / "missions" / "urban_search.yaml").world
    room = world.rooms[args.room]
    (x0, y0, _), (x1, y1, _) = room.box.lo, room.box.hi
    fig, axes = plt.subplots(1, len(PATTERNS), figsize=(3.0 * len(PATTERNS), 4.6))
    for ax, action in zip(axes, PATTERNS, strict=True):
        path = pattern_path(args.room, action)
        ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, lw=2.5,
                                   ec="0.25"))
        door = np.asarray(room.door.center)
        half = room.door.width / 2
        span = ([door[0] - half, door[0] + half], [door[1]] * 2) if room.door.normal_axis == 1 \
            else ([door[0]] * 2, [door[1] - half, door[1] + half])
        ax.plot(*span, color="white", lw=4, solid_capstyle="butt")
        ax.plot(*span, color="tab:orange", lw=1.2, ls=":", label="door")
        ax.plot(path[:, 0], path[:, 1], "-", color="tab:blue", lw=1.6)
        ax.plot(*path[0, :2], "o", color="tab:green", ms=7, label="start")
        ax.plot(*path[-1, :2], "x", color="tab:red", ms=9, mew=2, label="end")
        ax.set_title(action.replace("_", " "), fontsize=11)
        ax.set_aspect("equal")
        ax.set_xlim(x0 - 0.3, x1 + 0.3)
        ax.set_ylim(y0 - 0.3, y1 + 0.3)
        ax.tick_params(labelsize=8)
    axes[0].legend(loc="lower left", fontsize=8, framealpha=0.9)
    fig.suptitle(f"UAV search patterns in room {args.room} "
                 f"({x1 - x0:.1f} x {y1 - y0:.1f} m), flown at {world.name} flight height",
                 fontsize=11)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
