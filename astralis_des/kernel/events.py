"""Event records: time, kind, robot and payload, of a kind the catalogue declares
(:mod:`astralis_des.kernel.catalogue`); handed to every sink as they happen."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import simpy

from astralis_des.kernel.catalogue import EVENTS, EventKind

Record = dict[str, Any]
AS_IS = frozenset({str, int, bool})  # types plain() returns as they are
Sink = Callable[[Record], None]


class EventLog:
    """Append-only list of records; sinks see each one the moment it is emitted."""

    def __init__(self, env: simpy.Environment) -> None:
        self.env = env
        self.records: list[Record] = []
        self.sinks: list[Sink] = []
        self.watchers: list[Sink] = []  # called once every sink has a record (a fork)
        self.in_order = True  # every record's time at or after the one before
        self._kinds: dict[str, tuple[int, EventKind]] = {}  # kind -> (registry version, it)
        self._t: tuple[object, float] = (None, 0.0)  # the last time emitted, rounded

    def emit(self, kind: str, robot: str | None = None, *, at: float | None = None,
             **payload: Any) -> Record:
        """Record an event now, or ``at`` a time between now and the next pending event (the
        physics stepper's time inside a macro-step). A kind, or a field, the catalogue does
        not declare is refused (``ValueError``, ``LookupError``): a bug, not a record."""
        known = self._kinds.get(kind)
        if known is None or known[0] != EVENTS.version:
            known = self._kinds[kind] = (EVENTS.version, EVENTS.get(kind))
        known[1].check(robot, payload)
        t = self.env.now if at is None else at
        if t is not self._t[0]:  # the same instant's events share one rounding
            self._t = (t, round(float(t), 6))
        record: Record = {"t": self._t[1], "kind": kind}
        if robot is not None:
            record["robot"] = robot
        for k, v in payload.items():
            kind_of = type(v)
            record[k] = v if v is None or kind_of in AS_IS else (
                round(v, 6) if kind_of is float else plain(v))
        if self.records and record["t"] < self.records[-1]["t"]:
            self.in_order = False
        self.records.append(record)
        for sink in self.sinks:
            sink(record)
        for watcher in self.watchers:
            watcher(record)
        return record

    def of_kind(self, kind: str) -> list[Record]:
        return [r for r in self.records if r["kind"] == kind]


def plain(value: Any) -> Any:
    """JSON-ready, deterministic: numpy to Python, floats rounded to the micrometre/microsecond."""
    kind = type(value)  # the plain types by identity first: most values are
    if kind is float:
        return round(value, 6)
    if value is None or kind in AS_IS:
        return value
    if kind is dict:
        return {k if type(k) is str else str(k): plain(v) for k, v in value.items()}
    if kind is list or kind is tuple:
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, np.generic):
        return plain(value.item())
    if isinstance(value, float):
        return round(value, 6)
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    return value
