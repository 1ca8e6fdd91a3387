"""UAVs pass over walkers: a UAV with a person or an avatar on a collision course, or
standing on its route, climbs over it (holding while it climbs, if the walker moves; where
it cannot climb, until the walker has passed) and comes back down once it is past."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.physics.courses import closest_approach, on_route
from astralis_des.physics.drivers import SAMPLE
from astralis_des.world.geometry import FloatArray

if TYPE_CHECKING:
    from astralis_des.physics.courses import Body

CLIMB_MARGIN = 0.3  # m a climbing UAV keeps above a walker's head
MAX_CLIMB = 0.8  # m: a UAV climbs at most this far above its course
CLIMB_SOON = 3.0  # s: a walker this close to meeting a UAV makes it climb
MOVER_AHEAD = np.linspace(0.0, 3.0, 16)  # s ahead at which a mover's path is looked at


def _walks(kind: str) -> bool:
    """Whether a body of ``kind`` walks: a person of the team, or an avatar of the scene."""
    return kind == "avatar" or (kind in KIND_DEFAULTS and KIND_DEFAULTS[kind].person)


class Climber:
    """The climbs of the UAVs of one co-simulation. ``fits(robot, points)``: where its body
    is clear."""

    def __init__(self, fits: Callable[[str, FloatArray], np.ndarray]) -> None:
        self.fits = fits

    def need(self, me: Body, others: list[Body], velocity: FloatArray, route: FloatArray,
             path_ahead: FloatArray, free: bool, paths: dict[str, FloatArray],
             lowest: float | None = None) -> tuple[float, list[Body]]:
        """How far a UAV going at ``velocity`` climbs (where it is, if ``free``: not under a
        door's lintel, nor about to be) to pass over a walker on a collision course with
        it, or standing on its ``route`` within ``CLIMB_SOON``; and the walkers that move it
        waits for (while it climbs; where it cannot, until they have passed; once up there,
        it flies on over them). ``paths``: where the movers near a moving robot will walk;
        ``lowest``: the bottom of its band where its course comes lowest ahead (a walker
        under the band now but over that counts: the UAV is coming down)."""
        need, moving = 0.0, []
        speed = float(np.linalg.norm(velocity))
        # where it will be at each of MOVER_AHEAD, going on along its path (and staying at
        # its end: it stops there)
        mine = path_ahead[np.minimum(np.round(speed * MOVER_AHEAD / SAMPLE).astype(int),
                                     len(path_ahead) - 1)]
        floor = me.base_z[0] if lowest is None else min(me.base_z[0], lowest)
        for other in others:
            if not _walks(other.kind) or other.z[1] < floor:
                continue
            clear = me.radius + other.radius + 0.3
            path = paths.get(other.name) if other.kind == "avatar" else None
            miss = float(np.linalg.norm(path - mine, axis=1).min()) if path is not None else \
                closest_approach(other.xy - me.xy, other.velocity - velocity, CLIMB_SOON)
            reach, off_route = on_route(route, other.xy, other.velocity)
            if miss < clear or (off_route < clear and reach < speed * CLIMB_SOON):
                need = max(need, other.z[1] + CLIMB_MARGIN - me.base_z[0])
                if float(np.linalg.norm(other.velocity)) > 0.05:
                    moving.append(other)
        need = min(need, MAX_CLIMB)
        if need <= 0.0:
            return 0.0, []
        if me.z[0] - me.base_z[0] >= need - 0.05:  # up there, it flies on
            moving = []
        centre = (me.base_z[0] + me.base_z[1]) / 2
        above = np.array([[*me.xy, centre + need]])
        return (need, moving) if free and self.fits(me.name, above).all() else \
            (0.0, moving)
