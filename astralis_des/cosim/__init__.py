"""Co-simulations behind one contract: ``execute(robot, motion) -> simpy.Event``.

``COSIMS`` maps a mission's ``fidelity`` to the class that runs its motions.
"""

from __future__ import annotations

from typing import Any

from astralis_des.registry import Registry

COSIMS: Registry[str, Any] = Registry("fidelity")

from astralis_des.cosim import kinematic  # noqa: E402,F401  (registers itself)


def load_fidelity(name: str) -> Any:
    """The co-simulation class of a fidelity; physics is imported only when asked for."""
    if name == "physics" and name not in COSIMS:
        from astralis_des.cosim import physics  # noqa: F401
    return COSIMS.get(name)
