"""The assignment rounds of a run: who is matched to which rooms, from where they stand, and
the record each round leaves (``rounds`` in the summary, an ``assignment`` event)."""

from __future__ import annotations

import math
import time
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
import simpy

from astralis_des.assignment import Agent, Assignment, RoomInfo, Weights, assign
from astralis_des.kernel.events import EventLog
from astralis_des.kernel.robot import Robot
from astralis_des.streams import stream

if TYPE_CHECKING:
    from astralis_des.mission.draws import RoomState
    from astralis_des.mission.loader import Mission
    from astralis_des.world.model import World


class AssignmentRounds:
    """The rounds of a :class:`~astralis_des.simulation.core.Simulation` (a part of it)."""

    mission: Mission
    world: World
    env: simpy.Environment
    log: EventLog
    rooms: dict[str, RoomState]
    rounds: list[dict[str, Any]]
    allocation_time: list[float]
    _weights: tuple[Any, Weights] | None = None  # the mission's weights, as a round takes them

    def assignment_round(self, segment: str, rooms: list[str], robots: list[Robot],
                         exclude: dict[str, set[str]] | None = None) -> Assignment:
        """Match ``robots`` to ``rooms``; ``exclude`` names the kinds that may not take a room
        (they searched it and saw too little)."""
        cfg = self.mission.spec.assignment
        agents, infos, weights, reachable = self.round_inputs(rooms, robots, exclude)
        started = time.perf_counter()
        plan = assign(agents, infos, weights, strategy=cfg.strategy, solver=cfg.solver,
                      high_risk=cfg.high_risk, high_messiness=cfg.high_messiness,
                      reachable=reachable, options=cfg.options.model_dump(),
                      rng=stream(self.mission.spec.seed, "assignment", len(self.rounds) + 1))
        self.allocation_time.append(time.perf_counter() - started)  # wall: not in the log
        self.record_round(segment, cfg.strategy, plan, infos)
        return plan

    def round_inputs(self, rooms: list[str], robots: list[Robot],
                     exclude: dict[str, set[str]] | None = None
                     ) -> tuple[list[Agent], list[RoomInfo], Weights, np.ndarray]:
        """What a round is given: the agents where they stand, the rooms as drawn, the
        mission's weights and who may take which room (reaches it, not ``exclude``d)."""
        exclude = exclude or {}
        agents = [Agent(r.id, r.kind, _xyz(r.position(self.env.now))) for r in robots]
        infos = [self.room_info(rid) for rid in rooms]
        return agents, infos, self.round_weights(), self.allowed(robots, rooms, exclude)

    def room_info(self, rid: str) -> RoomInfo:
        """A room as a round is given it: its centre and area, its risk and messiness as
        drawn (made again when a room change replaced either)."""
        state, kept = self.rooms[rid], self._infos.get(rid)
        if kept is None or kept[0] is not state.risk or kept[1] is not state.messiness:
            room = self.world.rooms[rid]
            kept = self._infos[rid] = (state.risk, state.messiness, RoomInfo(
                rid, room.center, state.risk, state.messiness, room.area))
        return kept[2]

    def round_weights(self) -> Weights:
        """The mission's W1 and W2 by kind, made again only when a fork changed them."""
        given = self.mission.spec.assignment.weights  # a frozen model: a change is a new one
        if self._weights is None or self._weights[0] is not given:
            self._weights = (given, Weights(given.risk.model_dump(),
                                            given.messiness.model_dump()))
        return self._weights[1]

    def allowed(self, robots: list[Robot], rooms: list[str],
                exclude: dict[str, set[str]] | None = None) -> np.ndarray:
        """``(robots, rooms)``: who may take which room: it gets there from where it is, and
        its kind is not ``exclude``d from the room (it saw too little of it)."""
        out = np.array([self.reaches(robot, rooms) for robot in robots],
                       dtype=bool).reshape(len(robots), len(rooms))
        for j, kinds in enumerate([exclude.get(rid) for rid in rooms] if exclude else ()):
            for i, robot in enumerate(robots):
                if kinds and robot.kind in kinds:
                    out[i, j] = False
        return out

    def record_round(self, segment: str, strategy: str, plan: Assignment,
                     infos: list[RoomInfo]) -> None:
        """A round in ``rounds`` and an ``assignment`` event: who was matched to what."""
        record: dict[str, Any] = {
            "round": len(self.rounds) + 1, "t": self.env.now, "segment": segment,
            "strategy": strategy, "agents": list(plan.agents), "rooms": list(plan.rooms),
            "risk": [i.risk for i in infos], "messiness": [i.messiness for i in infos],
            "costs": [[c if math.isfinite(c) else None for c in row]
                      for row in plan.costs.tolist()],
            "matching": [{"agent": p.agent, "room": p.room, "cost": p.cost, "action": p.action}
                         for p in plan.pairs],
            "unassigned": list(plan.unassigned),
        }
        if plan.info:  # a planner's report (the paper's strategies have none)
            record["info"] = plan.info
        self.rounds.append(record)
        self.log.emit("assignment", **{k: v for k, v in record.items() if k != "t"})

    def reaches(self, robot: Robot, room_ids: list[str]) -> list[bool]:
        """Can this robot's kind get to each room from where it is (stairs, ramps, doors)?"""
        if not room_ids:
            return []
        position = robot.position(self.env.now)
        known = self._reached.setdefault((robot.kind, position.tobytes()), {})
        missing = [room for room in room_ids if room not in known]
        if missing:
            here = self.world.on_floor(position)
            known.update(zip(missing, self.world.router.reachable_rooms(here, missing, robot.kind),
                             strict=True))
        return [known[room] for room in room_ids]

    @cached_property
    def _infos(self) -> dict[str, tuple[float, float, RoomInfo]]:
        """room -> (its risk, its messiness, its RoomInfo): the objects ``room_info`` made
        it from, so that any change makes it anew."""
        return {}

    @cached_property
    def _reached(self) -> dict[tuple[str, bytes], dict[str, bool]]:
        """(kind, where it stands) -> room -> whether it gets there: the world's answer,
        which depends on nothing else, asked once per place a robot is asked from (a robot
        free for a round stands still)."""
        return {}


def _xyz(p: np.ndarray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))
