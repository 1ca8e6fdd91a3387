"""The mission timeline: assignment rounds segment by segment, and the scheduled events."""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Generator
from typing import TYPE_CHECKING, Any, cast

import simpy

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
    from astralis_des.kernel.simulation import Simulation

Handler = Callable[["Simulation", Any], None]
TIMELINE_EVENTS: Registry[str, Handler] = Registry("timeline event")


def search(sim: Simulation) -> Generator[simpy.Event, Any, str]:
    """Search each segment in turn; a round matches the free agents to its pending rooms.

    A room whose search failed (no route, stuck) stays pending for the next round, up to
    ``max_attempts`` rounds; one whose searcher broke down (a fault, a crash) stays pending
    without using an attempt. Returns why the search stopped.
    """
    attempts: Counter[str] = Counter()
    max_attempts = sim.mission.spec.assignment.max_attempts
    if sim.mission.spec.assignment.start_at > 0:
        yield sim.env.timeout(sim.mission.spec.assignment.start_at)
    for segment in sim.mission.searched_segments():
        pending = list(sim.world.segments[segment].rooms)
        while pending:
            agents = [r for r in sim.robots.values() if not r.faulted]
            if not agents:
                sim.log.emit("team_lost", segment=segment)
                return "team_lost"
            plan = sim.assignment_round(segment, pending, agents)
            searches = dispatch(sim, plan)
            yield simpy.AllOf(sim.env, list(searches.values()))
            searcher = {p.room: p.agent for p in plan.pairs}
            for room, done in searches.items():
                outcome = cast(ActionResult, done.value)
                if outcome.ok:
                    pending.remove(room)
                    sim.searched.append(room)
                    continue
                if sim.robots[searcher[room]].faulted:
                    continue  # the robot broke, not the room: another takes it next round
                attempts[room] += 1
                if attempts[room] >= max_attempts:
                    pending.remove(room)
                    sim.log.emit("room_given_up", room=room, attempts=attempts[room])
    return "not_found"


def dispatch(sim: Simulation, plan: Assignment) -> dict[str, simpy.Event]:
    """Queue each matched agent's tasks, go to the door and search the room; the events
    succeed with the searches' results, by room."""
    searches = {}
    for pair in plan.pairs:
        sim.enqueue(pair.agent, "move", pair.room, {"point": "door"}, round=len(sim.rounds))
        searches[pair.room] = sim.enqueue(pair.agent, pair.action, pair.room,
                                          round=len(sim.rounds))
    return searches


def book(sim: Simulation, searches: dict[str, simpy.Event]) -> Generator[simpy.Event, Any, None]:
    """Count the rooms of a round asked for by hand as searched once their searches succeed."""
    yield simpy.AllOf(sim.env, list(searches.values()))
    sim.searched.extend(room for room, done in searches.items()
                        if cast(ActionResult, done.value).ok and room not in sim.searched)


def scheduled(sim: Simulation, event: Any) -> Generator[simpy.Event, Any, None]:
    yield sim.env.timeout(event.at - sim.env.now)
    TIMELINE_EVENTS.get(event.event)(sim, event)


@TIMELINE_EVENTS.register("fault")
def _fault(sim: Simulation, event: FaultEvent) -> None:
    sim.fault(sim.robots[event.robot], event.reason)


@TIMELINE_EVENTS.register("recover")
def _recover(sim: Simulation, event: RecoverEvent) -> None:
    sim.recover(sim.robots[event.robot])


@TIMELINE_EVENTS.register("room_change")
def _room_change(sim: Simulation, event: RoomChangeEvent) -> None:
    state = sim.rooms[event.room]
    changes = event.model_dump(include={"risk", "messiness", "sound"}, exclude_none=True)
    for key, value in changes.items():
        setattr(state, key, value)
    sim.log.emit("room_change", room=event.room, **changes)


@TIMELINE_EVENTS.register("command")
def _command(sim: Simulation, event: CommandEvent) -> None:
    sim.log.emit("command", event.robot, action=event.action, room=event.room,
                 params=dict(event.params), preempt=event.preempt)
    sim.enqueue(event.robot, event.action, event.room, dict(event.params), origin="timeline",
                preempt=event.preempt)


@TIMELINE_EVENTS.register("cancel")
def _cancel(sim: Simulation, event: CancelEvent) -> None:
    cancelled = sim.handler(event.robot).cancel(reason="cancelled by the timeline")
    sim.log.emit("cancel", event.robot, tasks=[t.id for t in cancelled])
