"""How long an agent takes, for the strategies that plan whole queues: travel by the kind's
distance rule (Eq. 1's: l2 for a UAV, Manhattan for the UGV and the human) at its cruise
speed, and a Table IV action by the room's floor area.

The seconds per square metre are those of the kinematic fidelity, measured over the searches of
40 scenarios x 3 strategies of ``studies/outcomes.yaml`` (``python tools/action_durations.py``
prints them again): a UAV flies any of its patterns in about 0.44 s/m^2, a person walks in and
looks in 0.38 s/m^2, the UGV observes from the corridor in 0.75 s/m^2 and peeks from the door in
0.24 s/m^2. A planner's estimate, not a promise: clutter and detours change the real time.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from astralis_des.kinds import KIND_DEFAULTS

SECONDS_PER_M2: dict[str, float] = {
    "spiral_inward": 0.437,
    "spiral_outward": 0.432,
    "sweep_horizontal": 0.439,
    "inspect": 0.377,
    "observe_corridor": 0.753,
    "sneak_peek": 0.238,
}
DEFAULT_SECONDS_PER_M2 = 0.5  # an action of a plug-in, not measured


def search_seconds(action: str, area: float) -> float:
    """Seconds a Table IV ``action`` takes in a room of ``area`` square metres."""
    return SECONDS_PER_M2.get(action, DEFAULT_SECONDS_PER_M2) * area


def travel_seconds(kind: str, start: NDArray[np.float64],
                   ends: NDArray[np.float64]) -> NDArray[np.float64]:
    """Seconds from ``start`` to each row of ``ends`` by the kind's distance rule and speed."""
    delta = np.abs(np.atleast_2d(ends) - np.asarray(start, dtype=float))
    defaults = KIND_DEFAULTS[kind]
    d = delta.sum(axis=1) if defaults.distance == "manhattan" else \
        np.sqrt((delta**2).sum(axis=1))
    return np.asarray(d / defaults.speed)
