"""astralis-des: an event-driven mission planner with a physics co-simulation for
heterogeneous UAV/UGV/human search teams.

    from astralis_des import load_mission, Simulation
    result = Simulation(load_mission("missions/urban_search.yaml")).run()
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"
__all__ = ["InputError", "Mission", "RunResult", "Simulation", "__version__", "load_mission"]

if TYPE_CHECKING:
    from astralis_des.errors import InputError
    from astralis_des.kernel.result import RunResult
    from astralis_des.kernel.simulation import Simulation
    from astralis_des.mission.loader import Mission, load_mission

_LAZY = {
    "InputError": "astralis_des.errors",
    "RunResult": "astralis_des.kernel.result",
    "Simulation": "astralis_des.kernel.simulation",
    "Mission": "astralis_des.mission.loader",
    "load_mission": "astralis_des.mission.loader",
}


def __getattr__(name: str) -> Any:
    """Import on first use, so that ``astralis --help`` starts fast."""
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'astralis_des' has no attribute {name!r}")
