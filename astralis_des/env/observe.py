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
    """Builds observations; what all agents share is built once per decision time."""

    def __init__(self, run: EpisodeRun) -> None:
        self.run = run
        sim = run.sim
        rooms = run.layout.rooms
        self._static = np.zeros((len(rooms), ROOM_COLUMNS), dtype=np.float32)
        for j, rid in enumerate(rooms):
            room = sim.world.rooms[rid]
            self._static[j, 8:11] = room.center
            self._static[j, 11] = room.area
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
        now = sim.env.now
        out = np.zeros((len(run.order), AGENT_COLUMNS), dtype=np.float32)
        for i, rid in enumerate(run.order):
            robot = sim.robots[rid]
            out[i, KINDS.index(robot.kind)] = 1.0
            out[i, 3:6] = robot.position(now)
            out[i, 6] = robot.heading
            handler = sim.handler(rid)
            hold = run.holds.get(rid)
            out[i, 7] = not run.idle(rid)
            out[i, 8] = robot.faulted
            out[i, 9] = hold is not None and not hold.processed
            out[i, 10] = rid in run.asked
            task = handler.current
            if task is not None and task.room in run.layout.room_index:
                out[i, 11] = run.layout.room_index[task.room] + 1
            if task is not None and task.action in SEARCHES:
                out[i, 12] = SEARCHES.index(task.action) + 1
        return out

    def _rooms(self) -> np.ndarray:
        run, sim = self.run, self.run.sim
        out = self._static.copy()
        pending, searched = set(run.pending), set(sim.searched)
        for j, rid in enumerate(run.layout.rooms):
            if rid in run.inflight:
                column = 2
            elif rid in searched:
                column = 3
            elif rid in run.given_up:
                column = 4
            else:  # open now (the segment's), or waiting for its segment
                column = 1 if rid in pending else 0
            out[j, column] = 1.0
            out[j, 5] = run.coverage.get(rid, 0.0)
            state = sim.rooms[rid]
            out[j, 6], out[j, 7] = state.risk, state.messiness
        return out

    def observe(self, agent: str) -> dict[str, Any]:
        run = self.run
        time, agents, rooms = self.shared()
        me = np.zeros(len(run.order), dtype=np.float32)
        me[run.order.index(agent)] = 1.0
        queue = np.zeros((QUEUE, 2), dtype=np.float32)
        handler = run.sim.handler(agent)
        tasks = ([handler.current] if handler.current is not None else []) + handler.queued
        for k, task in enumerate(tasks[:QUEUE]):
            queue[k, 0] = run.layout.room_index.get(task.room or "", -1) + 1
            queue[k, 1] = TASK_CODES.get(task.action, 0)
        return {"observation": {"time": time, "me": me, "agents": agents, "queue": queue,
                                "rooms": rooms},
                "action_mask": run.mask(agent)}

    def state(self) -> np.ndarray:
        time, agents, rooms = self.shared()
        return np.concatenate([time, agents.ravel(), rooms.ravel()])

