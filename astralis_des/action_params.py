"""The parameters each built-in Table I action takes: names, types, ranges and defaults.

Checked where a task is given (the mission's timeline when the file loads, the API and the
chat when the command arrives, :meth:`Simulation.enqueue` for everything else), so that a bad
value is a one-line error naming the parameter, and a robot never starts a task it cannot do.
An action without an entry here (a plug-in's) takes whatever it is given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Param:
    """A number in ``[low, high]`` (``None``: unbounded), or one of ``choices``."""

    doc: str
    default: Any = None
    low: float | None = None
    high: float | None = None
    choices: tuple[str, ...] | None = None

    def check(self, action: str, name: str, value: Any) -> Any:
        if self.choices is not None:
            if value not in self.choices:
                raise ValueError(f"{action}: {name} must be one of {', '.join(self.choices)} "
                                 f"(got {value!r})")
            return value
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"{action}: {name} must be a number (got {value!r})") from None
        if isinstance(value, bool) or not math.isfinite(number):
            raise ValueError(f"{action}: {name} must be a finite number (got {value!r})")
        if self.low is not None and number < self.low:
            raise ValueError(f"{action}: {name} must be at least {self.low:g} (got {number:g})")
        if self.high is not None and number > self.high:
            raise ValueError(f"{action}: {name} must be at most {self.high:g} (got {number:g})")
        return number


_SPACING = Param("m between lanes or rings (default: from the camera's footprint)", None,
                 0.1, 50.0)
PARAMS: dict[str, dict[str, Param]] = {
    "hover": {"duration": Param("s to hold position and look around", 10.0, 0.0, 86400.0)},
    "spiral_inward": {"spacing": _SPACING},
    "spiral_outward": {"spacing": _SPACING},
    "sweep_horizontal": {"spacing": _SPACING},
    "sweep_vertical": {"spacing": _SPACING},
    "take_off": {},
    "land": {},
    "inspect": {"inset": Param("m from the walls of the walk round the room", 1.0, 0.0, 20.0)},
    "sneak_peek": {"dwell": Param("s looking in from the door", 5.0, 0.0, 600.0)},
    "observe_corridor": {"dwell": Param("s looking from each spot of the corridor", 1.0, 0.0,
                                        600.0)},
    "move": {"point": Param("with a room: where in it", "center", choices=("center", "door")),
             "x": Param("m, a point to go to (with y)"), "y": Param("m"),
             "z": Param("m", 0.0), "look": Param("1: watch for the target on the way", 0.0,
                                                 0.0, 1.0)},
}


def check_params(action: str, params: dict[str, Any]) -> dict[str, Any]:
    """``params`` checked against ``action``'s own (numbers as floats); a ``ValueError`` with
    one line naming the parameter otherwise."""
    spec = PARAMS.get(action)
    if spec is None:
        return dict(params)
    out = {}
    for name, value in params.items():
        if name not in spec:
            known = ", ".join(spec) or "none"
            raise ValueError(f"{action} has no parameter '{name}' (its parameters: {known})")
        out[name] = spec[name].check(action, name, value)
    return out
