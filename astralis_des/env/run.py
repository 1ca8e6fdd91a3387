"""One episode: a mission run whose rounds the environment's agents decide.

The mission's own search process (:func:`astralis_des.simulation.timeline.search`) matches the
free agents to a segment's rooms, round after round. Here a process with the same book-keeping
(segments in order, rooms left for another kind when seen too little, attempts, rooms no agent
may take settled) stops the kernel at each *decision time*, when at least one agent is free:
its queue ran dry, a hold ended, or something on the timeline changed (a fault, a recovery,
a room change, a command). The free agents are asked; the others are busy and are not. Their
answers are committed together as one round (an ``assignment`` event, a ``move`` to the door and
the search for each room taken, as the paper's dispatch does) and the kernel runs to the next
decision time; the time in between costs nothing.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Generator
from pathlib import Path
from typing import Any

import numpy as np
import simpy

from astralis_des.actions import ACTIONS
from astralis_des.assignment import STRATEGIES, Assignment, Pair
from astralis_des.env.layout import CONTINUE, HOLD, WAIT, Layout, searches_of
from astralis_des.env.rewards import Progress
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import TaskStatus
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.mission.loader import Mission
from astralis_des.simulation import Simulation
from astralis_des.simulation.result import RunResult
from astralis_des.simulation.timeline import ALL, book_search, dispatch, groups, settle

SETTLE = 32  # zero-time passes a decision waits for the events of its instant
HEARD = frozenset({"fault", "recover", "room_change", "command", "cancel"})


class EpisodeRun:
    """A :class:`Simulation` driven decision time by decision time."""

    def __init__(self, mission: Mission, layout: Layout, *, label: str, hold_s: float,
                 out_dir: Path | None = None) -> None:
        self.layout = layout
        self.label = label  # the strategy the rounds are logged under
        self.hold_s = hold_s
        self.sim = Simulation(mission, out_dir=out_dir, searcher=self._search)
        self.order = list(self.sim.robots)
        self.asked: list[str] = []  # the agents deciding now, in team order
        self.offered: list[str] = []  # the rooms they may take now
        self.allowed: dict[str, set[str]] = {}  # per asked agent: the offered rooms it may take
        self.choices: dict[str, int] = {}  # answers so far at this decision time
        self._asking = 0  # counts the times asked and answered (masks are built per time)
        self._masks: dict[str, tuple[tuple[int, int, bool], np.ndarray]] = {}
        self._searches = {rid: layout.searches_by(robot.kind).tolist()  # room -> its actions
                          for rid, robot in self.sim.robots.items()}
        self.segment = ""
        self.pending: list[str] = []  # the segment's rooms not yet searched (or in flight)
        self.inflight: dict[str, tuple[str, simpy.Event]] = {}  # room -> searcher, its search
        self._rounds: list[list[str]] = []  # the rooms of each round not yet booked
        self.holds: dict[str, simpy.Event] = {}  # robot -> the end of its hold
        self.coverage: dict[str, float] = {}  # room -> the most of it a search saw
        self.given_up: set[str] = set()  # rooms no longer pending, not searched
        self.result: RunResult | None = None
        self._attempts: Counter[str] = Counter()
        self._ask = self.sim.env.event()
        self._reply: simpy.Event | None = None
        self._poke: simpy.Event | None = None
        self._seen = 0  # of sim.finished, accounted for in progress
        self._t = 0.0
        self._searched = 0
        self._found_told = False
        self.sim.log.sinks.append(self._heard)
        self.sim.start()
        self._run()

    # -- the kernel's side ---------------------------------------------------------------
    def _search(self, sim: Simulation) -> Generator[simpy.Event, Any, str]:
        start_at = sim.mission.spec.assignment.start_at
        if start_at > 0:
            yield sim.env.timeout(start_at)
        for segment, rooms in groups(sim.mission):
            self.segment, self.pending = segment, list(rooms)
            while self.pending:
                if sim.ended:  # the UAVs are landing: no more decisions
                    return "ended"
                for _ in range(SETTLE):  # the instant's other events first, so that every
                    if sim.env.peek() != sim.env.now:  # robot free at this time is asked at
                        break  # once (bounded: the physics stepper also waits for them)
                    yield sim.env.timeout(0)
                agents = [r for r in sim.robots.values() if not r.faulted]
                if not agents:
                    sim.log.emit("team_lost", segment=segment)
                    return "team_lost"
                offered = [r for r in self.pending if r not in self.inflight]
                free = [r for r in agents if self._free(r)]
                allowed = self._who_may(agents, free, offered)
                if allowed is None:
                    self._record(agents, offered, {})  # an empty round, as the paper logs it
                    for room in offered:
                        settle(sim, room, "no agent left that can search it")
                    break
                if free:
                    self._open(free, offered, allowed)
                    self._reply = sim.env.event()
                    self._ask.succeed()
                    yield self._reply
                    self._commit()
                self._poke = sim.env.event()
                if self.holds:
                    self.holds = {r: e for r, e in self.holds.items() if not e.processed}
                yield simpy.AnyOf(sim.env, [self._poke, *self.holds.values()])
                self._book()
        return "not_found"

    def _heard(self, record: dict[str, Any]) -> None:
        """Sees every event as it is logged: a robot's queue running dry, or a change on the
        timeline, makes a decision time."""
        kind = record["kind"]
        if kind == "room_given_up":
            self.given_up.add(record["room"])
        poke = self._poke
        if poke is None or poke.triggered:
            return
        if kind in HEARD or (kind == "task_finished" and (
                record.get("room") in self.inflight or self.idle(record["robot"]))):
            poke.succeed()

    def idle(self, robot_id: str) -> bool:
        """Whether the robot has nothing running and nothing queued."""
        handler = self.sim.handler(robot_id)
        return handler.current is None and not handler.waiting

    def _free(self, robot: Robot) -> bool:
        hold = self.holds.get(robot.id)
        return not robot.faulted and self.idle(robot.id) and (hold is None or hold.processed)

    def _who_may(self, agents: list[Robot], free: list[Robot], offered: list[str]
                 ) -> np.ndarray | None:
        """``(free, offered)``: which of the rooms each free agent may take; None when no
        search is in flight and no agent at all may take any (the rooms are settled)."""
        allowed = self._allowed(free, offered)
        if self.inflight or allowed.any():
            return allowed
        asked = {r.id for r in free}
        busy = [r for r in agents if r.id not in asked]  # looked at only when no free one may
        return allowed if self._allowed(busy, offered).any() else None

    def _allowed(self, robots: list[Robot], rooms: list[str]) -> np.ndarray:
        """``Simulation.allowed``: not tried by the kind, reached from where it stands."""
        return self.sim.allowed(robots, rooms, self.sim.tried)

    def _open(self, free: list[Robot], offered: list[str], allowed: np.ndarray) -> None:
        """Ask the ``free`` agents, who may take the ``allowed`` (``(free, offered)``) of the
        ``offered`` rooms."""
        self.asked, self.offered, self.choices = [r.id for r in free], offered, {}
        self._asking += 1
        self.allowed = {r.id: {room for room, ok in zip(offered, row, strict=True) if ok}
                        for r, row in zip(free, allowed.tolist(), strict=True)}

    def _commit(self) -> None:
        """The answers of this decision time: one round for the rooms taken, then holds."""
        picks = {}
        for agent in self.asked:
            action, room = self.layout.decode(self.choices.get(agent, WAIT))
            if room is not None:
                picks[agent] = (room, action)
        if picks:
            robots = [self.sim.robots[a] for a in self.asked]
            searches = dispatch(self.sim, self._record(robots, self.offered, picks))
            for agent, (room, _) in picks.items():
                self.inflight[room] = (agent, searches[room])
            self._rounds.append(list(searches))
        for agent in self.asked:
            if self.choices.get(agent) == HOLD:
                self._hold(self.sim.robots[agent])
        self.asked, self.choices = [], {}
        self._asking += 1

    def _hold(self, robot: Robot) -> None:
        if (robot.kind, "hover") in ACTIONS:
            self.sim.enqueue(robot.id, "hover", None, {"duration": self.hold_s}, origin="hold")
        else:
            self.holds[robot.id] = self.sim.env.timeout(self.hold_s)

    def _record(self, robots: list[Robot], rooms: list[str],
                picks: dict[str, tuple[str, str]]) -> Assignment:
        """Log the round as the mission's rounds are logged: the costs under the mission's
        strategy (for the record), the rooms taken, the agents that took none."""
        sim = self.sim
        agents, infos, weights, reachable = sim.round_inputs(rooms, robots, sim.tried)
        costs = np.where(reachable, STRATEGIES.get(sim.mission.spec.assignment.strategy)(
            agents, infos, weights), np.inf) if rooms else np.zeros((len(robots), 0))
        column = {room: j for j, room in enumerate(rooms)}
        pairs = tuple(Pair(a.id, picks[a.id][0], float(costs[i, column[picks[a.id][0]]]),
                           picks[a.id][1]) for i, a in enumerate(agents) if a.id in picks)
        plan = Assignment(tuple(a.id for a in agents), tuple(rooms), costs, pairs,
                          tuple(a.id for a in agents if a.id not in picks))
        sim.record_round(self.segment, self.label, plan, infos)
        return plan

    def _book(self) -> None:
        """Book the searches of each round once the last of them has ended, as the paper's
        rounds do (with a strategy that plans whole queues: each as it ends)."""
        one_by_one = self.segment == ALL
        for rooms in list(self._rounds):
            ended = [r for r in rooms if self.inflight[r][1].triggered]
            if not one_by_one and len(ended) < len(rooms):
                continue
            for room in ended:
                agent, done = self.inflight.pop(room)
                rooms.remove(room)
                book_search(self.sim, self.pending, self._attempts, {room: agent}, room, done)
            if not rooms:
                self._rounds.remove(rooms)

    # -- the environment's side ----------------------------------------------------------
    @property
    def ended(self) -> bool:
        return self.result is not None

    def mask(self, agent: str) -> np.ndarray:
        """The actions ``agent`` may take now (1) and may not (0)."""
        return self._mask(agent).copy()

    def _mask(self, agent: str) -> np.ndarray:
        """:meth:`mask`, shared: built once per agent while the answers stay as they are."""
        key = (self._asking, len(self.choices), self.ended)
        known = self._masks.get(agent)
        if known is not None and known[0] == key:
            return known[1]
        out = np.zeros(self.layout.size, dtype=np.int8)
        if self.ended or agent not in self.asked or agent in self.choices:
            out[CONTINUE] = 1
        else:
            out[WAIT] = out[HOLD] = 1
            taken = {self.layout.decode(c)[1] for c in self.choices.values()}
            index, searches = self.layout.room_index, self._searches[agent]
            for room in self.allowed[agent]:  # a few rooms: item by item beats fancy indexing
                if room not in taken:
                    for action in searches[index[room]]:
                        out[action] = 1
        self._masks[agent] = (key, out)
        return out

    def refusal(self, agent: str, action: int) -> str | None:
        """Why ``agent`` may not take ``action`` now, or None."""
        try:
            name, room = self.layout.decode(int(action))
        except (IndexError, TypeError, ValueError):
            return f"action {action!r} is not an action index (0..{self.layout.size - 1})"
        if self._mask(agent)[int(action)]:
            return None
        if agent not in self.asked:
            return f"{agent} is busy: only continue"
        if room is None:
            return f"{name}: only for an agent that is busy"
        if room not in self.offered:
            return f"{room} is not open now (searched, being searched or a later segment)"
        if name not in searches_of(self.sim.robots[agent].kind):
            return f"a {self.sim.robots[agent].kind} has no {name}"
        if room not in self.allowed[agent]:
            return f"{agent} cannot search {room} (no way there, or its kind saw too little)"
        return f"{room} was taken by another agent at this decision time"

    def choose(self, agent: str, action: int) -> str | None:
        """Record ``agent``'s answer; a refused one counts as ``wait`` and says why."""
        why = self.refusal(agent, action)
        if agent in self.asked and agent not in self.choices:
            self.choices[agent] = WAIT if why is not None else int(action)
        return why

    @property
    def complete(self) -> bool:
        """Whether every asked agent has answered."""
        return all(a in self.choices for a in self.asked)

    def advance(self, refused: dict[str, int] | None = None) -> Progress:
        """Commit the answers and run the kernel to the next decision time (or the end);
        ``refused``: the actions refused at this decision time, by agent."""
        assert self._reply is not None and not self.ended
        self._reply.succeed()
        self._ask = self.sim.env.event()
        self._run()
        return self.progress(refused)

    def _run(self) -> None:
        if not self.sim.ended:
            self.sim.env.run(until=self._ask)
        if self.sim.ended:
            self.asked = []
            self.result = self.sim.finish()

    def close(self) -> None:
        """End the run where it is (its outputs are written, marked ``interrupted``)."""
        if self.result is None:
            self.asked = []
            self.result = self.sim.finish()

    def progress(self, refused: dict[str, int] | None = None) -> Progress:
        """What happened since the last call."""
        sim, cfg = self.sim, self.sim.mission.spec.assignment
        new = sim.finished[self._seen:] if self._seen < len(sim.finished) else ()
        self._seen = len(sim.finished)
        risk = clutter = 0.0
        failed: Counter[str] = Counter()
        for task, res in new:
            if res.status == TaskStatus.FAILED:
                failed[task.robot] += 1
            if task.room is None or task.action in ("move", "hover"):
                continue
            if res.coverage is not None:
                self.coverage[task.room] = max(self.coverage.get(task.room, 0.0), res.coverage)
            hazard = KIND_DEFAULTS[sim.robots[task.robot].kind].hazard
            if hazard == "risk" and sim.rooms[task.room].risk >= cfg.high_risk:
                risk += res.end - res.start
            if hazard == "messiness" and sim.rooms[task.room].messiness >= cfg.high_messiness:
                clutter += res.end - res.start
        now = sim.env.now
        dt, self._t = now - self._t, now
        searched, self._searched = len(sim.searched) - self._searched, len(sim.searched)
        found = sim.found.triggered and not self._found_told
        self._found_told = self._found_told or found
        return Progress(dt, found, risk, clutter,
                        dict(failed), dict(refused or {}), searched,
                        self.result.outcome if self.result is not None else None)


