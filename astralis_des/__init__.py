"""astralis-des: an event-driven mission planner with a physics co-simulation for
heterogeneous UAV/UGV/human search teams.

    from astralis_des import load_mission, Simulation
    result = Simulation(load_mission("missions/urban_search.yaml")).run()
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from astralis_des.version import __version__

__all__ = ["InputError", "Mission", "RunResult", "Simulation", "__version__", "load_mission"]

if TYPE_CHECKING:
    from astralis_des.errors import InputError
    from astralis_des.mission.loader import Mission, load_mission
    from astralis_des.simulation import Simulation
    from astralis_des.simulation.result import RunResult

_LAZY = {
    "InputError": "astralis_des.errors",
    "RunResult": "astralis_des.simulation.result",
    "Simulation": "astralis_des.simulation.core",
    "Mission": "astralis_des.mission.loader",
    "load_mission": "astralis_des.mission.loader",
}


def __getattr__(name: str) -> Any:
    """Import on first use, so that ``astralis --help`` starts fast."""
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'astralis_des' has no attribute {name!r}")
