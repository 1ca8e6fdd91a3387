"""Co-simulations behind one contract: ``execute(robot, motion) -> simpy.Event``.

``COSIMS`` maps a mission's ``fidelity`` to the class that runs its motions.
"""

from __future__ import annotations

from collections.abc import Callable

from astralis_des.kernel.contracts import CoSim, Host
from astralis_des.plugins import COSIMS

__all__ = ["COSIMS", "load_fidelity"]


def load_fidelity(name: str) -> Callable[[Host], CoSim]:
    """The co-simulation class of a fidelity; physics is imported only when asked for."""
    if name == "physics" and name not in COSIMS:
        from astralis_des.cosim import physics  # noqa: F401
    return COSIMS.get(name)
