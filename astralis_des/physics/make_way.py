"""Making way: where a robot standing idle in another's way goes (the local layer asks, the
co-simulation moves it there)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.physics.local import DOOR_BUSY
from astralis_des.world.geometry import FloatArray, segments_hit_boxes

if TYPE_CHECKING:
    from astralis_des.kernel.robot import Robot
    from astralis_des.physics.engine import Engine

ASIDE_STEPS = (1.0, 1.5, 2.0, 3.0, 4.0)  # m: how far a robot making way may go (a
# Husky in a corridor 2.5 m wide goes along it, ahead of the one that asks)
ASIDE_DIRECTIONS = 16


def aside(cosim: Engine, robot: Robot, here: FloatArray, path: FloatArray,
          asker_kind: str) -> FloatArray | None:
    """The nearest spot (at ``here``'s height, on the same floor) where ``robot`` is clear of
    ``path`` by both bodies' radii and a margin, fits among walls and furniture (and can
    set off from there again: a Husky's rectangle fits at some heading), is not in a
    doorway, and is reached in a straight line that does not take it past the robot asking
    (nearer than the two touch): where it goes to make way, or None."""
    angles = np.arange(ASIDE_DIRECTIONS) * (2 * math.pi / ASIDE_DIRECTIONS)
    rings = [here + np.column_stack([np.cos(angles), np.sin(angles), np.zeros(len(angles))]) * r
             for r in ASIDE_STEPS]
    spots = np.vstack(rings)
    touching = KIND_DEFAULTS[robot.kind].passes_by + KIND_DEFAULTS[asker_kind].passes_by
    clear_of = touching + 0.3
    gaps = np.linalg.norm(spots[:, None, :2] - path[None, :, :2], axis=2).min(axis=1)
    floor = cosim.world.floor_below(here - np.array([0.0, 0.0, robot.height]))
    near_door = cosim.world.near_doorway(spots, floor, DOOR_BUSY)
    for index in np.flatnonzero((gaps >= clear_of) & ~near_door):
        spot = spots[index]
        leg = here + (spot - here) * np.linspace(0.0, 1.0, 6)[:, None]
        to_asker = np.linalg.norm(leg[:, :2] - path[0, :2], axis=1)
        if np.any(to_asker < min(touching, float(to_asker[0])) - 1e-9):
            continue  # not past the robot that asks (it stands at the start of its path)
        if cosim.fits(robot.id, leg).all() and cosim.stands(robot.id, spot[None, :])[0] and \
                not segments_hit_boxes(here[None, :], spot[None, :], cosim.world.solid_array)[0]:
            return spot
    return None
