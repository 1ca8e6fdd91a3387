"""The mission timeline: assignment rounds segment by segment, and the scheduled events."""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Generator
from functools import partial
from typing import TYPE_CHECKING, Any, cast

import simpy

from astralis_des.assignment import STRATEGIES
from astralis_des.kernel.tasks import ActionResult
from astralis_des.mission.spec import (
    CancelEvent,
    CommandEvent,
    FaultEvent,
    RecoverEvent,
    RoomChangeEvent,
)
from astralis_des.registry import Registry

if TYPE_CHECKING:
    from astralis_des.assignment import Assignment
    from astralis_des.mission.loader import Mission
    from astralis_des.simulation.contracts import Run

Handler = Callable[["Run", Any], None]
TIMELINE_EVENTS: Registry[str, Handler] = Registry("timeline event")
ALL = "all"  # the segment of a round given every searched room


def search(sim: Run, before_round: Callable[[], None] | None = None
           ) -> Generator[simpy.Event, Any, str]:
    """Search each segment in turn; a round matches the free agents to its pending rooms.

    A room whose search failed (no route, stuck) stays pending for the next round, up to
    ``max_attempts`` rounds; one whose searcher broke down (a fault, a crash) stays pending
    without using an attempt. A search that saw less of the room than ``min_coverage`` leaves
    it pending for an agent of a kind that has not searched it yet; when no such agent is
    left, the room counts as searched as far as the team could see it. ``before_round`` is
    called as each round is about to be decided (a fork at a round). A strategy changed
    mid-run (a fork) from one that plans a segment at a time to one that plans the whole
    mission, or back, regroups the rooms left (:func:`regroup`). Returns why the search
    stopped.
    """
    attempts: Counter[str] = Counter()
    spec = sim.mission.spec.assignment
    if spec.start_at > 0:
        yield sim.env.timeout(spec.start_at)
    left = groups(sim.mission)
    while left:
        segment, pending = left.pop(0)
        while pending:
            if sim.ended:  # the UAVs are landing: no more rounds
                return "ended"
            if before_round is not None:
                before_round()
            if _whole(sim.mission) != (segment == ALL):
                left = regroup(sim.mission, [(segment, pending), *left])
                break
            agents = [r for r in sim.robots.values() if not r.faulted]
            if not agents:
                sim.log.emit("team_lost", segment=segment)
                return "team_lost"
            plan = sim.assignment_round(segment, pending, agents, exclude=sim.tried)
            if not plan.pairs:  # no agent may take any pending room: settle them
                for room in list(pending):
                    settle(sim, room, "no agent left that can search it")
                    pending.remove(room)
                break
            searches = dispatch(sim, plan)
            searcher = {p.room: p.agent for p in plan.pairs}
            yield from _as_they_end(sim, searches, segment == ALL,
                                    partial(book_search, sim, pending, attempts, searcher))
    return "not_found"


def book_search(sim: Run, pending: list[str], attempts: Counter[str],
                searcher: dict[str, str], room: str, done: simpy.Event) -> None:
    """A search that ended: its room searched, left pending for another kind (seen too
    little) or another robot (its own broke down), or tried once more, up to the limit."""
    if sim.ended:  # cut short by the mission's end: nothing to book
        return
    outcome = cast(ActionResult, done.value)
    robot = sim.robots[searcher[room]]
    if outcome.ok and not _undercovered(sim, room, robot, outcome):
        pending.remove(room)
        sim.searched.append(room)
        return
    if outcome.ok or robot.faulted:
        return  # seen too little, or the robot broke: another takes it next round
    attempts[room] += 1
    if attempts[room] >= sim.mission.spec.assignment.max_attempts:
        pending.remove(room)
        sim.log.emit("room_given_up", room=room, attempts=attempts[room])


def _as_they_end(sim: Run, searches: dict[str, simpy.Event], one_by_one: bool,
                 book: Callable[[str, simpy.Event], None]) -> Generator[simpy.Event, Any, None]:
    """Book the round's searches: all together once they have ended (a segment's round), or
    each as it ends (whole queues: a room counts as searched as soon as it is, not when the
    last queue runs dry, which a found target may never let happen)."""
    if not one_by_one:
        yield simpy.AllOf(sim.env, list(searches.values()))
        for room, done in searches.items():
            book(room, done)
        return
    left = dict(searches)
    while left:
        yield simpy.AnyOf(sim.env, list(left.values()))
        for room in [r for r, e in left.items() if e.processed]:
            book(room, left.pop(room))


def groups(mission: Mission) -> list[tuple[str, list[str]]]:
    """The rooms a round is given: a segment's at a time, as the paper's rounds do, or every
    searched room at once (``all``) for a strategy that plans whole queues."""
    segments = mission.searched_segments()
    world = mission.world
    if _whole(mission):
        return [(ALL, [r for seg in segments for r in world.segments[seg].rooms])]
    return [(seg, list(world.segments[seg].rooms)) for seg in segments]


def regroup(mission: Mission, left: list[tuple[str, list[str]]]
            ) -> list[tuple[str, list[str]]]:
    """The rooms ``left`` (the current group's pending ones, then the later groups') as the
    mission's strategy takes them now: all in one group (``all``), or by segment in the
    search order; empty groups are dropped."""
    rooms = [r for _, group in left for r in group]
    if _whole(mission):
        return [(ALL, rooms)] if rooms else []
    regrouped = [(seg, [r for r in mission.world.segments[seg].rooms if r in rooms])
                 for seg in mission.searched_segments()]
    return [(seg, group) for seg, group in regrouped if group]


def _whole(mission: Mission) -> bool:
    """Does the mission's strategy plan the whole mission at once?"""
    return STRATEGIES.get(mission.spec.assignment.strategy).whole_mission


def _undercovered(sim: Run, room: str, robot: Any, outcome: ActionResult) -> bool:
    """Whether a search that succeeded saw too little of ``room`` and another kind of agent
    can still search it; a ``room_undercovered`` event says so either way."""
    threshold = sim.mission.spec.assignment.min_coverage
    if outcome.coverage is None or outcome.coverage >= threshold:
        return False
    sim.tried.setdefault(room, set()).add(robot.kind)
    others = sorted({r.kind for r in sim.robots.values() if not r.faulted} - sim.tried[room])
    sim.log.emit("room_undercovered", robot.id, room=room, coverage=outcome.coverage,
                 threshold=threshold, requeued=bool(others), kinds_left=others)
    return bool(others)


def settle(sim: Run, room: str, why: str) -> None:
    """A pending room no agent may take: searched as far as seen, if it was; else given up."""
    if room in sim.tried:
        sim.searched.append(room)
        sim.log.emit("room_searched_undercovered", room=room, reason=why)
    else:
        sim.log.emit("room_given_up", room=room, attempts=0, reason=why)


def dispatch(sim: Run, plan: Assignment) -> dict[str, simpy.Event]:
    """Queue each matched agent's tasks, go to the door and search the room; the events
    succeed with the searches' results, by room."""
    searches = {}
    for pair in plan.pairs:
        sim.enqueue(pair.agent, "move", pair.room, {"point": "door"}, round=len(sim.rounds))
        searches[pair.room] = sim.enqueue(pair.agent, pair.action, pair.room,
                                          round=len(sim.rounds))
    return searches


def book(sim: Run, searches: dict[str, simpy.Event]) -> Generator[simpy.Event, Any, None]:
    """Count the rooms of a round asked for by hand as searched once their searches succeed."""
    yield simpy.AllOf(sim.env, list(searches.values()))
    sim.searched.extend(room for room, done in searches.items()
                        if cast(ActionResult, done.value).ok and room not in sim.searched)


def scheduled(sim: Run, event: Any) -> Generator[simpy.Event, Any, None]:
    yield sim.env.timeout(event.at - sim.env.now)
    TIMELINE_EVENTS.get(event.event)(sim, event)


@TIMELINE_EVENTS.register("fault")
def _fault(sim: Run, event: FaultEvent) -> None:
    sim.fault(sim.robots[event.robot], event.reason)


@TIMELINE_EVENTS.register("recover")
def _recover(sim: Run, event: RecoverEvent) -> None:
    sim.recover(sim.robots[event.robot])


@TIMELINE_EVENTS.register("room_change")
def _room_change(sim: Run, event: RoomChangeEvent) -> None:
    state = sim.rooms[event.room]
    changes = event.model_dump(include={"risk", "messiness", "sound"}, exclude_none=True)
    for key, value in changes.items():
        setattr(state, key, value)
    sim.log.emit("room_change", room=event.room, **changes)


@TIMELINE_EVENTS.register("command")
def _command(sim: Run, event: CommandEvent) -> None:
    sim.log.emit("command", event.robot, action=event.action, room=event.room,
                 params=dict(event.params), preempt=event.preempt)
    sim.enqueue(event.robot, event.action, event.room, dict(event.params), origin="timeline",
                preempt=event.preempt)


@TIMELINE_EVENTS.register("cancel")
def _cancel(sim: Run, event: CancelEvent) -> None:
    cancelled = sim.handler(event.robot).cancel(reason="cancelled by the timeline")
    sim.log.emit("cancel", event.robot, tasks=[t.id for t in cancelled])
