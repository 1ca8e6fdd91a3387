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
    """Builds observations from tables kept for the episode: a decision time writes the
    robots' rows and those of the rooms that changed (kinds, the rooms' places and areas are
    written once); what all agents share is handed out as copies made once per decision
    time, so an observation a learner keeps stays as it was."""

    def __init__(self, run: EpisodeRun) -> None:
        self.run = run
        sim = run.sim
        rooms = run.layout.rooms
        self._room_table = np.zeros((len(rooms), ROOM_COLUMNS), dtype=np.float32)
        for j, rid in enumerate(rooms):
            room = sim.world.rooms[rid]
            self._room_table[j, 8:11] = room.center
            self._room_table[j, 11] = room.area
        self._room_rows: list[tuple[Any, ...] | None] = [None] * len(rooms)
        self._room_states = [(rid, sim.rooms[rid]) for rid in rooms]
        self._agent_table = np.zeros((len(run.order), AGENT_COLUMNS), dtype=np.float32)
        for i, rid in enumerate(run.order):
            self._agent_table[i, KINDS.index(sim.robots[rid].kind)] = 1.0
        self._team = [(rid, sim.robots[rid], sim.handler(rid)) for rid in run.order]
        self._me = {rid: np.eye(len(run.order), dtype=np.float32)[i]
                    for i, rid in enumerate(run.order)}
        self._key: tuple[Any, ...] | None = None
        self._shared: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def shared(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``time``, ``agents`` and ``rooms``, as they are now."""
        run = self.run
        key = (run.sim.env.now, len(run.sim.log.records), tuple(run.asked))
        if self._key == key and self._shared is not None:
            return self._shared
        self._update_agents()
        self._update_rooms()
        self._key, self._shared = key, (np.array([run.sim.env.now], dtype=np.float32),
                                        self._agent_table.copy(), self._room_table.copy())
        return self._shared

    def _update_agents(self) -> None:
        run = self.run
        now, index, holds, asked = run.sim.env.now, run.layout.room_index, run.holds, run.asked
        rows = []
        for rid, robot, handler in self._team:  # where they are: every row, every time
            hold = holds.get(rid)
            task = handler.current
            if task is None:
                room = action = 0
            else:
                room = index.get(task.room, -1) + 1 if task.room else 0
                action = TASK_CODES[task.action] if task.action in SEARCHES else 0
            rows.append((*robot.position(now).tolist(), robot.heading,
                         task is not None or handler.waiting, robot.faulted,
                         hold is not None and not hold.processed, rid in asked, room, action))
        self._agent_table[:, 3:] = rows

    def _update_rooms(self) -> None:
        """The rows whose state, coverage, risk or messiness changed. A value counts as the
        same only when it is the same object (so a 0.0 that became -0.0 is written too)."""
        run = self.run
        # a room's state: being searched, else searched, else given up, else open now (the
        # segment's), else waiting for its segment (0): the later ones written over
        codes = dict.fromkeys(run.pending, 1)
        codes.update(dict.fromkeys(run.given_up, 4))
        codes.update(dict.fromkeys(run.sim.searched, 3))
        codes.update(dict.fromkeys(run.inflight, 2))
        coverage, table, rows = run.coverage, self._room_table, self._room_rows
        for j, (rid, state) in enumerate(self._room_states):
            code = codes.get(rid, 0)
            seen, risk, mess = coverage.get(rid, 0.0), state.risk, state.messiness
            last = rows[j]
            if (last is None or last[0] != code or last[1] is not seen or last[2] is not risk
                    or last[3] is not mess):
                rows[j] = (code, seen, risk, mess)
                table[j, :5] = 0.0
                table[j, code] = 1.0
                table[j, 5:8] = seen, risk, mess

    def observe(self, agent: str) -> dict[str, Any]:
        run = self.run
        time, agents, rooms = self.shared()
        queue = np.zeros((QUEUE, 2), dtype=np.float32)
        handler = run.sim.handler(agent)
        tasks = handler.queued
        if handler.current is not None:
            tasks = [handler.current, *tasks]
        index = run.layout.room_index
        for k, task in enumerate(tasks[:QUEUE]):
            queue[k] = index.get(task.room or "", -1) + 1, TASK_CODES.get(task.action, 0)
        return {"observation": {"time": time, "me": self._me[agent].copy(), "agents": agents,
                                "queue": queue, "rooms": rooms},
                "action_mask": run.mask(agent)}

    def state(self) -> np.ndarray:
        time, agents, rooms = self.shared()
        return np.concatenate([time, agents.ravel(), rooms.ravel()])
