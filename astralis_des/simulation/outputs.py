"""Where a run's outputs come from: ``OUTPUTS`` maps a name to a function that opens them
for a simulation and an output folder (``astralis_des.sinks.files`` registers ``files``: the
event log, the summary and the Rerun recording). The sinks sit above the simulation and subscribe
to its event stream; the simulation finds them here, by name, without importing them."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from astralis_des.registry import Registry

Opener = Callable[[Any, Path | None], Any]  # (simulation, folder) -> its open outputs
OUTPUTS: Registry[str, Opener] = Registry("outputs", plugins=("astralis_des.sinks.files",))
