"""astralis_des.env.observe: observations from tables equal ones built from scratch."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("pettingzoo")

from astralis_des.actions import ACTIONS
from astralis_des.env import MissionEnv, ParallelMissionEnv, random_policy
from astralis_des.env.layout import CONTINUE, SEARCHES
from astralis_des.env.observe import AGENT_COLUMNS, QUEUE, ROOM_COLUMNS, TASK_CODES
from astralis_des.env.run import EpisodeRun
from astralis_des.kinds import KINDS

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "missions" / "urban_search.yaml"


def _agents(run: EpisodeRun) -> np.ndarray:
    sim, now = run.sim, run.sim.env.now
    out = np.zeros((len(run.order), AGENT_COLUMNS), dtype=np.float32)
    for i, rid in enumerate(run.order):
        robot, hold, task = sim.robots[rid], run.holds.get(rid), sim.handler(rid).current
        out[i, KINDS.index(robot.kind)] = 1.0
        out[i, 3:6] = robot.position(now)
        out[i, 6:11] = (robot.heading, not run.idle(rid), robot.faulted,
                        hold is not None and not hold.processed, rid in run.asked)
        if task is not None and task.room in run.layout.room_index:
            out[i, 11] = run.layout.room_index[task.room] + 1
        if task is not None and task.action in SEARCHES:
            out[i, 12] = SEARCHES.index(task.action) + 1
    return out


def _rooms(run: EpisodeRun) -> np.ndarray:
    sim = run.sim
    out = np.zeros((len(run.layout.rooms), ROOM_COLUMNS), dtype=np.float32)
    for j, rid in enumerate(run.layout.rooms):
        if rid in run.inflight:
            out[j, 2] = 1.0
        elif rid in sim.searched:
            out[j, 3] = 1.0
        elif rid in run.given_up:
            out[j, 4] = 1.0
        else:
            out[j, 1 if rid in run.pending else 0] = 1.0
        room, state = sim.world.rooms[rid], sim.rooms[rid]
        out[j, 5:8] = run.coverage.get(rid, 0.0), state.risk, state.messiness
        out[j, 8:11], out[j, 11] = room.center, room.area
    return out


def _mask(run: EpisodeRun, agent: str) -> np.ndarray:
    out = np.zeros(run.layout.size, dtype=np.int8)
    if run.ended or agent not in run.asked or agent in run.choices:
        out[CONTINUE] = 1
        return out
    out[1] = out[2] = 1  # wait, hold
    taken = {run.layout.decode(c)[1] for c in run.choices.values()}
    kind = run.sim.robots[agent].kind
    for room in run.allowed[agent] - taken:
        for action in SEARCHES:
            if (kind, action) in ACTIONS:
                out[run.layout.index(room, action)] = 1
    return out


def _from_scratch(run: EpisodeRun, agent: str) -> dict[str, Any]:
    me = np.zeros(len(run.order), dtype=np.float32)
    me[run.order.index(agent)] = 1.0
    queue = np.zeros((QUEUE, 2), dtype=np.float32)
    handler = run.sim.handler(agent)
    tasks = ([handler.current] if handler.current is not None else []) + handler.queued
    for k, task in enumerate(tasks[:QUEUE]):
        queue[k] = run.layout.room_index.get(task.room or "", -1) + 1, \
            TASK_CODES.get(task.action, 0)
    return {"observation": {"time": np.array([run.sim.env.now], dtype=np.float32), "me": me,
                            "agents": _agents(run), "queue": queue, "rooms": _rooms(run)},
            "action_mask": _mask(run, agent)}


def _same(got: dict[str, Any], want: dict[str, Any]) -> None:
    assert got["action_mask"].dtype == want["action_mask"].dtype
    assert got["action_mask"].tobytes() == want["action_mask"].tobytes()
    for key, value in want["observation"].items():
        array = got["observation"][key]
        assert (array.dtype, array.shape) == (value.dtype, value.shape), key
        assert array.tobytes() == value.tobytes(), key


@pytest.mark.parametrize("seed", [1, 4, 9])
def test_every_observation_of_an_episode_is_the_one_built_from_scratch(seed: int) -> None:
    """Bit for bit, each agent's view at each of its turns, random policy, whole episodes."""
    env = MissionEnv(DEFAULT)
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    turns = 0
    for agent in env.agent_iter():
        obs, _, term, trunc, _ = env.last()
        run = env.mission_run
        _same(obs, _from_scratch(run, agent))
        for other in env.agents:  # everyone's view, asked or not
            _same(env.observe(other), _from_scratch(run, other))
        state = np.concatenate([[np.float32(run.sim.env.now)], _agents(run).ravel(),
                                _rooms(run).ravel()]).astype(np.float32)
        assert env.state().tobytes() == state.tobytes()
        env.step(None if term or trunc else random_policy(obs, rng))
        turns += 1
    assert turns > 5 and env.mission_run.ended


def test_the_parallel_env_observes_as_from_scratch_each_step() -> None:
    """Every agent, every step of a parallel episode."""
    env = ParallelMissionEnv(DEFAULT)
    obs, _ = env.reset(seed=2)
    rng = np.random.default_rng(2)
    while env.agents:
        for agent in env.agents:
            _same(obs[agent], _from_scratch(env.mission_run, agent))
        obs, *_ = env.step({a: random_policy(obs[a], rng) for a in env.agents})


def test_a_mask_handed_out_is_the_callers_own() -> None:
    """Writing into one observation's mask changes neither the next nor what is refused."""
    env = MissionEnv(DEFAULT)
    env.reset()
    mask = env.observe("uav1")["action_mask"]
    mask[:] = 0
    assert env.observe("uav1")["action_mask"][1] == 1  # wait
    env.step(1)
    assert "refused" not in env.infos["uav1"]


def test_an_observation_kept_stays_as_it_was() -> None:
    """The tables are updated in place: what a learner kept from earlier turns is not."""
    env = MissionEnv(DEFAULT)
    env.reset(seed=3)
    rng = np.random.default_rng(3)
    kept = []
    for _ in env.agent_iter():
        obs, _, term, trunc, _ = env.last()
        kept.append((obs, {k: v.copy() for k, v in obs["observation"].items()}))
        env.step(None if term or trunc else random_policy(obs, rng))
    assert len(kept) > 5
    for obs, copy in kept:
        for key, value in copy.items():
            assert obs["observation"][key].tobytes() == value.tobytes(), key
