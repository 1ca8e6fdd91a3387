"""What an agent observes, as Gymnasium spaces.

Each agent's observation is a ``Dict`` with its ``action_mask`` (PettingZoo's convention) and
an ``observation``:

- ``time``: simulated seconds, ``(1,)``.
- ``me``: which row of ``agents`` is this agent, one-hot ``(N,)``.
- ``agents``: per robot of the team, ``(N, 13)``: kind one-hot (uav, ugv, human), x, y, z,
  heading, busy, faulted, holding, asked now, its running task's room (index + 1, 0: none)
  and action (index into the layout's searches + 1; ``move`` and ``hover`` count as 0).
- ``queue``: this agent's tasks, running first, ``(4, 2)``: room (index + 1) and action
  (index + 1, as above; 8 for ``move``, 9 for ``hover``); zeros past its end.
- ``rooms``: per room of the layout, ``(R, 12)``: state one-hot (later segment, open now,
  being searched, searched, given up), the most coverage a search saw, risk, messiness,
  x, y, z of its centre, floor area (m^2).

``state()`` is the time, ``agents`` and ``rooms`` flattened (for a centralised critic).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from gymnasium import spaces

from astralis_des.env.layout import SEARCHES
from astralis_des.kinds import KINDS

if TYPE_CHECKING:
    from astralis_des.env.run import EpisodeRun

BOUND = 1e5  # m, s: the box every value lies in
QUEUE = 4
AGENT_COLUMNS = 13
ROOM_COLUMNS = 12
TASK_CODES = {**{a: k + 1 for k, a in enumerate(SEARCHES)}, "move": len(SEARCHES) + 1,
              "hover": len(SEARCHES) + 2}


def observation_space(n_agents: int, n_rooms: int, n_actions: int) -> spaces.Dict:
    def box(*shape: int) -> spaces.Box:
        return spaces.Box(-BOUND, BOUND, shape, dtype=np.float32)

    inner = spaces.Dict({"time": spaces.Box(0.0, BOUND, (1,), dtype=np.float32),
                         "me": spaces.Box(0.0, 1.0, (n_agents,), dtype=np.float32),
                         "agents": box(n_agents, AGENT_COLUMNS), "queue": box(QUEUE, 2),
                         "rooms": box(n_rooms, ROOM_COLUMNS)})
    return spaces.Dict({"observation": inner,
                        "action_mask": spaces.Box(0, 1, (n_actions,), dtype=np.int8)})


def state_space(n_agents: int, n_rooms: int) -> spaces.Box:
    size = 1 + n_agents * AGENT_COLUMNS + n_rooms * ROOM_COLUMNS
    return spaces.Box(-BOUND, BOUND, (size,), dtype=np.float32)


class Observer:
    """Builds observations; what all agents share is built once per decision time, from
    tables of what does not change in an episode (kinds, the rooms' places and areas)."""

    def __init__(self, run: EpisodeRun) -> None:
        self.run = run
        sim = run.sim
        rooms = run.layout.rooms
        self._static = np.zeros((len(rooms), ROOM_COLUMNS), dtype=np.float32)
        for j, rid in enumerate(rooms):
            room = sim.world.rooms[rid]
            self._static[j, 8:11] = room.center
            self._static[j, 11] = room.area
        self._kinds = np.zeros((len(run.order), AGENT_COLUMNS), dtype=np.float32)
        for i, rid in enumerate(run.order):
            self._kinds[i, KINDS.index(sim.robots[rid].kind)] = 1.0
        self._me = {rid: np.eye(len(run.order), dtype=np.float32)[i]
                    for i, rid in enumerate(run.order)}
        self._rows = np.arange(len(rooms))
        self._key: tuple[Any, ...] | None = None
        self._shared: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def shared(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``time``, ``agents`` and ``rooms``, as they are now."""
        run = self.run
        key = (run.sim.env.now, len(run.sim.log.records), tuple(run.asked))
        if self._key == key and self._shared is not None:
            return self._shared
        self._key, self._shared = key, (np.array([run.sim.env.now], dtype=np.float32),
                                        self._agents(), self._rooms())
        return self._shared

    def _agents(self) -> np.ndarray:
        run, sim = self.run, self.run.sim
        now, index = sim.env.now, run.layout.room_index
        rows = []
        for rid in run.order:
            robot = sim.robots[rid]
            hold = run.holds.get(rid)
            task = sim.handler(rid).current
            room = index.get(task.room, -1) + 1 if task is not None and task.room else 0
            action = TASK_CODES[task.action] if task is not None and task.action in SEARCHES \
                else 0
            rows.append((*robot.position(now).tolist(), robot.heading, not run.idle(rid),
                         robot.faulted, hold is not None and not hold.processed,
                         rid in run.asked, room, action))
        out = self._kinds.copy()
        out[:, 3:] = rows
        return out

    def _rooms(self) -> np.ndarray:
        run, sim = self.run, self.run.sim
        out = self._static.copy()
        pending, searched = set(run.pending), set(sim.searched)
        states, coverage, risk, messiness = [], [], [], []
        for rid in run.layout.rooms:
            if rid in run.inflight:
                states.append(2)
            elif rid in searched:
                states.append(3)
            elif rid in run.given_up:
                states.append(4)
            else:  # open now (the segment's), or waiting for its segment
                states.append(1 if rid in pending else 0)
            coverage.append(run.coverage.get(rid, 0.0))
            state = sim.rooms[rid]
            risk.append(state.risk)
            messiness.append(state.messiness)
        out[self._rows, states] = 1.0
        out[:, 5], out[:, 6], out[:, 7] = coverage, risk, messiness
        return out

    def observe(self, agent: str) -> dict[str, Any]:
        run = self.run
        time, agents, rooms = self.shared()
        queue = np.zeros((QUEUE, 2), dtype=np.float32)
        handler = run.sim.handler(agent)
        tasks = ([handler.current] if handler.current is not None else []) + handler.queued
        for k, task in enumerate(tasks[:QUEUE]):
            queue[k, 0] = run.layout.room_index.get(task.room or "", -1) + 1
            queue[k, 1] = TASK_CODES.get(task.action, 0)
        return {"observation": {"time": time, "me": self._me[agent].copy(), "agents": agents,
                                "queue": queue, "rooms": rooms},
                "action_mask": run.mask(agent)}

    def state(self) -> np.ndarray:
        time, agents, rooms = self.shared()
        return np.concatenate([time, agents.ravel(), rooms.ravel()])
