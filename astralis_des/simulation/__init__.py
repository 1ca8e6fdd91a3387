"""The composition root: :class:`Simulation` builds one run from a mission and the registries
(actions, fidelities, strategies, timeline events, outputs) and wires the plug-ins together.
Nothing below this layer imports it; the plug-ins see it through the kernel's contracts."""

from __future__ import annotations

from astralis_des.simulation.core import Simulation
from astralis_des.simulation.result import RunResult

__all__ = ["RunResult", "Simulation"]
