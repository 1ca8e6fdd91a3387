"""Fork a run at a decision: run the mission as it is up to a fork point, then on with changes.

No snapshot is taken: a run is deterministic (every draw derives from the mission's seed), so
running the same mission again reproduces the original up to the fork point byte for byte;
there the changes are made, a ``fork`` event says where and what, and the run goes on.

The fork points (:data:`TRIGGERS`):

- ``round:N``: just before assignment round N is decided; round N is the first under the
  changes (a fault at the fork is in place before it, so round N does without that robot).
- ``event:N``: right after the N-th line of the event log; what the changes schedule at that
  time happens once the moment that wrote line N is over.
- ``time:T``: at simulated time T, after every event before T and before any at T.

What can change at a fork: the assignment settings (the strategy, its options, the weights,
the thresholds, ``max_attempts``, ``min_coverage``: from the next round), rooms' risk,
messiness and sound (``rooms.set``: a ``room_change`` at the fork) and events appended to the
timeline (``timeline+=``; without ``at`` they happen at the fork); ``outputs`` apply to the
whole run. Anything else is refused (one line).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from typing import TYPE_CHECKING, Any, Protocol

from astralis_des.errors import InputError
from astralis_des.kernel.events import Record
from astralis_des.mission.changes import (
    Change,
    Changes,
    apply_changes,
    blame,
    check_changed,
    parse_changes,
    show_path,
)
from astralis_des.mission.spec import RoomChangeEvent
from astralis_des.registry import Registry
from astralis_des.simulation.contracts import Run
from astralis_des.simulation.timeline import TIMELINE_EVENTS, scheduled, search
from astralis_des.yamlio import format_path

if TYPE_CHECKING:
    from collections.abc import Generator

    import simpy

    from astralis_des.mission.loader import Mission
    from astralis_des.simulation.result import RunResult

Leaf = tuple[tuple[Any, ...], Any]  # a changed key of the mission file, and its new value
MID_RUN = (("assignment", "strategy"), ("assignment", "options"), ("assignment", "weights"),
           ("assignment", "high_risk"), ("assignment", "high_messiness"),
           ("assignment", "solver"), ("assignment", "max_attempts"),
           ("assignment", "min_coverage"))  # read afresh at each round
WHOLE_RUN = (("outputs",),)  # what the run writes: from its start, fork or not
ROOMS = ("rooms", "set")
ALLOWED = ("at a fork only the assignment settings, rooms.set and events appended with "
           "timeline+= change (docs/howto/fork.md); from the start (no fork) any key does")


Searcher = Callable[[Any], "Generator[simpy.Event, Any, str]"]


class ForkedRun(Run, Protocol):
    """What a fork sees of the run it forks (:class:`~astralis_des.simulation.Simulation`)."""

    mission: Mission  # a fork changes it mid-run
    searcher: Searcher

    @property
    def started(self) -> bool: ...

    def advance(self, until: float | None = None) -> bool: ...
    def finish(self) -> RunResult: ...


class ForkNotReached(InputError):
    """The run ended before its fork point: ``result`` is the run, unchanged (and written)."""

    def __init__(self, message: str, result: RunResult) -> None:
        super().__init__(message, key="--fork-at")
        self.result = result


@dataclass(frozen=True)
class ForkPoint:
    """Where a run forks: ``round:N``, ``event:N`` or ``time:T``."""

    kind: str
    value: float

    @classmethod
    def parse(cls, text: str) -> ForkPoint:
        kind, _, number = text.partition(":")
        if kind not in TRIGGERS:
            raise InputError(f"give round:N, event:N or time:T (got {text!r})",
                             key="--fork-at")
        trigger = TRIGGERS.get(kind)
        pattern = r"[0-9]+(\.[0-9]*)?|\.[0-9]+" if trigger.timed else r"[0-9]+"
        if not re.fullmatch(pattern, number.strip()) or (
                not trigger.timed and int(number) < 1):
            raise InputError(f"{kind}:{trigger.symbol} takes {trigger.number} (got {text!r})",
                             key="--fork-at")
        return cls(kind, float(number))

    @property
    def trigger(self) -> Trigger:
        return TRIGGERS.get(self.kind)

    def __str__(self) -> str:
        number = f"{self.value:.6f}".rstrip("0").rstrip(".")
        return f"{self.kind}:{number}"


@dataclass(frozen=True)
class Trigger:
    """A kind of fork point: what its number is, and how a run reaches it (``reach`` is
    called before the run starts; the fork's ``apply`` makes the changes there)."""

    symbol: str  # N or T, for the messages
    number: str
    timed: bool  # its number is the fork's time (a count of rounds or lines, else)
    asked: bool  # the search asks it before each round (Fork.searcher)
    reach: Callable[[Fork, ForkedRun], None]


TRIGGERS: Registry[str, Trigger] = Registry("fork point")


@dataclass
class Fork:
    """A fork checked against its mission: the changes to make and where; ``record`` is its
    ``fork`` event once the run reached it."""

    point: ForkPoint
    changed: Mission  # the whole mission as it is from the fork on
    changes: dict[str, Any]  # the keys changed mid-run (as --set spells them), new values
    added: list[tuple[Any, bool]]  # timeline events to add, and whether at the fork (``at``
    # left out: its value is only a placeholder)
    original: Mission | None = None  # the mission it forks
    said: list[Change] = field(default_factory=list)  # the changes as given, for errors
    probe: bool = False  # only find the fork's time (a fork with events at given times)
    times_checked: bool = False  # the events added at given times, against the fork's
    record: Record | None = None
    passed: bool = False  # the run had ended when it came to the point

    @property
    def trigger(self) -> Trigger:
        return self.point.trigger

    def searcher(self, sim: ForkedRun, base: Searcher) -> Searcher:
        """The search process ``sim`` runs: at a round fork, the mission's own, which asks
        the fork before each round."""
        if not self.trigger.asked:
            return base
        if base is not search:
            raise ValueError("a fork at a round needs the mission's own search process")
        return partial(search, before_round=partial(self._before_round, sim))

    def _before_round(self, sim: ForkedRun) -> None:
        if len(sim.rounds) + 1 >= self.point.value:
            self.apply(sim)

    def run(self, sim: ForkedRun, make: Callable[[Mission], ForkedRun]) -> RunResult:
        """Run ``sim`` to its end through the fork point; raise :class:`ForkNotReached` (the
        result in it) if the run ended before it. ``make`` builds a run of a mission (the
        ``Simulation`` class), to time the fork when events are added at given times."""
        if sim.started:
            raise ValueError("a fork runs a simulation from its start: this one has started")
        self.check_times(make)
        self.record, self.passed = None, False
        sim.mission = whole_run(sim.mission, self)
        sim.searcher = self.searcher(sim, sim.searcher)
        try:  # as Simulation.run: an interrupt while starting still ends the outputs
            self.point.trigger.reach(self, sim)
            sim.advance()
        finally:
            result = sim.finish()
        if self.record is None:
            raise ForkNotReached(self._missed(result), result)
        return result

    def check_times(self, make: Callable[[Mission], ForkedRun] | None) -> None:
        """Refuse (one line) an event added at a given time before the fork. At a time fork
        that is known at once; at a round or an event it takes a run of the original to the
        fork point, without outputs (``make`` builds it: ``Simulation``)."""
        timed = [(i, e.at) for i, (e, at_fork) in enumerate(self.added) if not at_fork]
        if self.times_checked or not timed or self.original is None:
            return
        if self.trigger.timed:
            when: float | None = self.point.value
        else:
            assert make is not None, "a round or an event fork is timed by a run"
            when = _fork_time(self, make(self.original))
        kept = len(self.original.spec.timeline)
        for i, at in timed:
            if when is not None and at < when - 1e-9:
                raise blame(self.said, f"timeline[{kept + i}].at", f"{at:g} s is before the "
                            f"fork ({self.point} comes at t = {when:.6g} s)")
        self.times_checked = True

    def _missed(self, result: RunResult) -> str:
        return (f"{self.point} was never reached: the run ended ({result.outcome}) at t = "
                f"{result.end_time:.1f} s after {len(result.rounds)} rounds and "
                f"{len(result.events)} events; the run went on unchanged")

    def apply(self, sim: ForkedRun, *, now: bool = True) -> None:
        """Fork here: the mission's changes in place, a ``fork`` event, the events added to
        the timeline (those due now at once, unless ``now`` is false: a fork inside another
        process's step schedules them for the same time)."""
        if self.record is not None or self.passed:
            return
        if sim.ended:
            self.passed = True
            return
        t = float(sim.env.now)
        if self.probe:
            raise _Reached(t)
        added = [e.model_copy(update={"at": t}) if at_fork else e for e, at_fork in self.added]
        spec = self.changed.spec.model_copy(
            update={"timeline": [*sim.mission.spec.timeline, *added]})
        sim.mission = replace(sim.mission, spec=spec)
        self.record = sim.log.emit(
            "fork", point=str(self.point), changes=self.changes,
            timeline=[e.model_dump(mode="json", exclude_none=True) for e in added],
            rounds=len(sim.rounds), lines=len(sim.log.records))
        for event in added:
            if now and event.at <= t:
                TIMELINE_EVENTS.get(event.event)(sim, event)
            else:
                sim.env.process(scheduled(sim, event))


class _Reached(Exception):  # a probe's stop at the fork, not an error
    def __init__(self, t: float) -> None:
        super().__init__(t)
        self.t = t


# -- the fork points -------------------------------------------------------------------------
def _reach_round(fork: Fork, sim: ForkedRun) -> None:
    """Round N: the search asks the fork before each round (:meth:`Fork.searcher`)."""


def _reach_event(fork: Fork, sim: ForkedRun) -> None:
    """Line N: a watcher of the event log, called once every sink has the line."""
    def watch(record: Record) -> None:
        if len(sim.log.records) >= fork.point.value:
            sim.log.watchers.remove(watch)
            fork.apply(sim, now=False)

    sim.log.watchers.append(watch)


def _reach_time(fork: Fork, sim: ForkedRun) -> None:
    """Time T: the run advances to T (every event before it), forks, and goes on."""
    if not sim.advance(until=fork.point.value):
        fork.apply(sim)


TRIGGERS.register("round")(Trigger("N", "a round number from 1", timed=False, asked=True,
                                   reach=_reach_round))
TRIGGERS.register("event")(Trigger("N", "a line number of the event log from 1", timed=False,
                                   asked=False, reach=_reach_event))
TRIGGERS.register("time")(Trigger("T", "simulated seconds", timed=True, asked=False,
                                  reach=_reach_time))


# -- a fork checked before the run -----------------------------------------------------------
def prepare(mission: Mission, at: str | ForkPoint, changes: Changes) -> Fork:
    """The fork of ``mission`` at ``at`` with ``changes`` (as ``--set``), checked: a change
    that cannot be made mid-run, or an event added before the fork, is one-line bad input."""
    point = at if isinstance(at, ForkPoint) else ForkPoint.parse(at)
    limit = mission.spec.time_limit
    if point.trigger.timed and point.value >= limit:
        raise InputError(f"{point} is not before the mission's time_limit ({limit:g} s): "
                         "the run would end first", key="--fork-at")
    parsed = parse_changes(changes)
    if not parsed:
        raise InputError("a fork needs at least one change (--set KEY=VALUE)", key="--fork-at")
    before = mission.spec.model_dump(mode="json")
    data = apply_changes(before, parsed)
    kept = len(mission.spec.timeline)
    timeline = data.get("timeline")
    new = timeline[kept:] if isinstance(timeline, list) else []
    at_fork = [isinstance(e, dict) and e.get("at") is None for e in new]
    for event, now in zip(new, at_fork, strict=True):
        if now:  # a placeholder for the check: the fork's time when it comes
            event["at"] = point.value if point.trigger.timed else 0.0
    changed = check_changed(mission, data, parsed)
    after = changed.spec.model_dump(mode="json")
    leaves = _diff(before, after)
    _refuse_fixed(leaves, parsed)
    if after["timeline"][:kept] != before["timeline"]:
        raise blame(parsed, "timeline", "only events appended (timeline+=) change the "
                    "timeline at a fork")
    added = [*zip(changed.spec.timeline[kept:], at_fork, strict=True),
             *((e, True) for e in _room_changes(leaves))]
    fork = Fork(point, changed, {show_path(p): v for p, v in leaves if _mid_run(p)}, added,
                mission, parsed)
    if point.trigger.timed:
        fork.check_times(None)
    return fork


def whole_run(mission: Mission, fork: Fork) -> Mission:
    """``mission`` with the fork's changes that apply to the whole run (its outputs)."""
    return replace(mission, spec=mission.spec.model_copy(
        update={"outputs": fork.changed.spec.outputs}))


def _diff(before: Any, after: Any, path: tuple[Any, ...] = ()) -> list[Leaf]:
    """The keys whose values differ, each to its deepest mapping (a list is one value)."""
    if isinstance(after, dict) and before is None:
        before = {}  # a mapping the file left out (rooms.set[R])
    if isinstance(before, dict) and isinstance(after, dict):
        return [leaf for key in [*before, *(k for k in after if k not in before)]
                for leaf in _diff(before.get(key), after.get(key), (*path, key))]
    return [] if before == after else [(path, after)]


def _mid_run(path: tuple[Any, ...]) -> bool:
    return any(path[:len(p)] == p for p in (*MID_RUN, ROOMS))


def _refuse_fixed(leaves: list[Leaf], changes: list[Change]) -> None:
    for path, value in leaves:
        if _mid_run(path) or path == ("timeline",) or any(
                path[:len(p)] == p for p in WHOLE_RUN):
            if path[:2] == ROOMS and value is None:
                raise blame(changes, format_path(path), "a room's drawn value cannot come "
                            "back at a fork: give the value it is to take")
            continue
        raise blame(changes, format_path(path), f"cannot change mid-run: {ALLOWED}")


def _room_changes(leaves: list[Leaf]) -> list[RoomChangeEvent]:
    """``rooms.set`` changed: a ``room_change`` at the fork per room (``at`` a placeholder)."""
    props: dict[str, dict[str, Any]] = {}
    for path, value in leaves:
        if path[:2] == ROOMS:
            props.setdefault(path[2], {})[path[3]] = value
    return [RoomChangeEvent(event="room_change", at=0.0, room=room, **values)
            for room, values in props.items()]


def _fork_time(fork: Fork, sim: ForkedRun) -> float | None:
    """The simulated time ``sim`` (a run of the original, without outputs) comes to the fork
    point, or None if it never does."""
    probe = replace(fork, probe=True)
    sim.searcher = probe.searcher(sim, sim.searcher)
    try:
        probe.point.trigger.reach(probe, sim)
        sim.advance()
    except _Reached as reached:
        return reached.t
    finally:
        sim.cosim.close()
    return None
