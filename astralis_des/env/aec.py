"""``MissionEnv``: PettingZoo's agent-environment-cycle API over the mission kernel.

The agent selected is a robot whose task has ended (the one that ends next in simulated time;
robots free at the same time in team order); ``step(action)`` records its next macro-action,
and once every robot free at that time has answered, the kernel runs to the next decision
time. A busy robot is never asked.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

from pettingzoo import AECEnv

from astralis_des.env.base import Front
from astralis_des.env.rewards import Progress, RewardFn
from astralis_des.mission.loader import Mission


class MissionEnv(Front, AECEnv[str, dict[str, Any], int]):
    """A mission as an AEC environment. See :class:`astralis_des.env.base.Episodes` for the
    arguments."""

    metadata: ClassVar[dict[str, Any]] = {"name": "astralis_mission_v0", "render_modes": [],
                                          "is_parallelizable": True}

    def __init__(self, mission: Mission | str | Path, *, fidelity: str | None = None,
                 time_limit: float | None = None, reward: RewardFn | None = None,
                 label: str = "env", hold_s: float = 10.0,
                 out_dir: str | Path | None = None) -> None:
        super().__init__()
        self._open(mission, fidelity=fidelity, time_limit=time_limit, reward=reward,
                   label=label, hold_s=hold_s, out_dir=out_dir)

    def reset(self, seed: int | None = None, options: dict[str, Any] | None = None) -> None:
        self.episodes.start(seed)
        self.agents = list(self.possible_agents)
        self.rewards = dict.fromkeys(self.agents, 0.0)
        self._cumulative_rewards = dict.fromkeys(self.agents, 0.0)
        self.terminations = dict.fromkeys(self.agents, False)
        self.truncations = dict.fromkeys(self.agents, False)
        self.infos: dict[str, dict[str, Any]] = {a: {} for a in self.agents}
        self._select()

    def observe(self, agent: str) -> dict[str, Any]:
        assert self.episodes.observer is not None
        return self.episodes.observer.observe(agent)

    def step(self, action: Any) -> None:
        agent = self.agent_selection
        if self.terminations[agent] or self.truncations[agent]:
            self._was_dead_step(action)
            return
        run = self.episodes.run
        assert run is not None
        self._cumulative_rewards[agent] = 0.0
        self._clear_rewards()
        why = run.choose(agent, action)
        refused = {agent: 1} if why is not None else {}
        self.infos[agent] = {"refused": why} if why is not None else {}
        if run.complete:
            progress = run.advance(refused)
            self.rewards = self.episodes.rewards_of(progress, self.agents)
            terminated, truncated = self.episodes.ended_how()
            for a in self.agents:
                self.terminations[a], self.truncations[a] = terminated, truncated
                if run.result is not None:
                    self.infos[a] = {**self.infos.get(a, {}), "outcome": run.result.outcome}
        elif refused:
            self.rewards[agent] = float(self.episodes.reward(
                Progress(0.0, False, 0.0, 0.0, refused=refused), agent))
        self._select()
        self._accumulate_rewards()

    def _select(self) -> None:
        run = self.episodes.run
        assert run is not None
        waiting = [a for a in run.asked if a not in run.choices]
        if waiting and not run.ended:
            self.agent_selection = waiting[0]
        elif self.agents:
            self.agent_selection = self.agents[0]
