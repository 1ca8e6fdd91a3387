"""Every random draw of a run comes from its seed, through one generator per purpose.

A purpose has its own stream (and a room or a plan its own key within it), so drawing more
for one purpose never shifts another: adding a room's furniture does not move the target.
"""

from __future__ import annotations

import numpy as np

STREAMS = {"rooms": 1, "target": 2, "avatar": 3, "clutter": 4, "movers": 5, "sensing": 6,
           "study": 7, "assignment": 8, "gnss": 9, "barometer": 10, "magnetometer": 11}
# study: a scenario's own draws (room values, starts, segment); assignment: a round's (the
# random strategy); gnss, barometer, magnetometer: a member's (keyed by its place in the team)


def stream(seed: int, purpose: str, *keys: int) -> np.random.Generator:
    """The generator for ``purpose`` (and ``keys`` within it) of a run seeded ``seed``."""
    return np.random.default_rng([seed, STREAMS[purpose], *keys])
