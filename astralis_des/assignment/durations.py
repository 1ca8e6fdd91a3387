"""How long an agent takes, for the strategies that plan whole queues: travel by the kind's
distance rule (Eq. 1's: l2 for a UAV, Manhattan for the UGV and the human) at its cruise
speed, and a Table IV action by the room's floor area.

The seconds per square metre (the actions' records' ``seconds_per_m2``) are those of the
kinematic fidelity, measured over the searches of 40 scenarios x 3 strategies of
``studies/outcomes.yaml`` (``python tools/action_durations.py`` prints them again): a UAV flies
any of its patterns in about 0.44 s/m^2, a person walks in and looks in 0.38 s/m^2, the UGV
observes from the corridor in 0.75 s/m^2 and peeks from the door in 0.24 s/m^2. A planner's
estimate, not a promise: clutter and detours change the real time.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.plugins import ACTIONS

DEFAULT_SECONDS_PER_M2 = 0.5  # an action of a plug-in, not measured


def seconds_per_m2(kind: str, action: str) -> float:
    """The record's measure for ``kind``'s ``action``, else :data:`DEFAULT_SECONDS_PER_M2`."""
    measured = ACTIONS.get((kind, action)).seconds_per_m2 if (kind, action) in ACTIONS else None
    return DEFAULT_SECONDS_PER_M2 if measured is None else measured


def search_seconds(kind: str, action: str, area: float) -> float:
    """Seconds ``kind``'s Table IV ``action`` takes in a room of ``area`` square metres."""
    return seconds_per_m2(kind, action) * area


def travel_seconds(kind: str, start: NDArray[np.float64],
                   ends: NDArray[np.float64]) -> NDArray[np.float64]:
    """Seconds from ``start`` to each row of ``ends`` by the kind's distance rule and speed."""
    delta = np.abs(np.atleast_2d(ends) - np.asarray(start, dtype=float))
    defaults = KIND_DEFAULTS[kind]
    d = delta.sum(axis=1) if defaults.distance == "manhattan" else \
        np.sqrt((delta**2).sum(axis=1))
    return np.asarray(d / defaults.speed)
