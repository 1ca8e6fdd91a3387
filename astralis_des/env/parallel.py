"""``ParallelMissionEnv``: PettingZoo's parallel API over the mission kernel.

Each ``step`` is one decision time: the robots free now act (their masks allow ``wait``,
``hold`` and the rooms they may search); the busy ones get a mask that allows only
``continue`` (anything else is refused, with the reason in their info). Two robots that pick the
same room: the first in team order takes it, the other is refused and waits.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

from pettingzoo import ParallelEnv

from astralis_des.env.base import Front
from astralis_des.env.layout import CONTINUE
from astralis_des.env.rewards import RewardFn
from astralis_des.mission.loader import Mission


class ParallelMissionEnv(Front, ParallelEnv[str, dict[str, Any], int]):
    """A mission as a parallel environment. See :class:`astralis_des.env.base.Episodes` for
    the arguments."""

    metadata: ClassVar[dict[str, Any]] = {"name": "astralis_mission_parallel_v0",
                                          "render_modes": []}

    def __init__(self, mission: Mission | str | Path, *, fidelity: str | None = None,
                 time_limit: float | None = None, reward: RewardFn | None = None,
                 label: str = "env", hold_s: float = 10.0,
                 out_dir: str | Path | None = None) -> None:
        self._open(mission, fidelity=fidelity, time_limit=time_limit, reward=reward,
                   label=label, hold_s=hold_s, out_dir=out_dir)

    def reset(self, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
        self.episodes.start(seed)
        self.agents = list(self.possible_agents)
        return self._observations(), {a: {} for a in self.agents}

    def _observations(self) -> dict[str, Any]:
        observer = self.episodes.observer
        assert observer is not None
        return {a: observer.observe(a) for a in self.agents}

    def step(self, actions: dict[str, Any]) -> tuple[dict[str, Any], dict[str, float],
                                                      dict[str, bool], dict[str, bool],
                                                      dict[str, dict[str, Any]]]:
        run = self.episodes.run
        assert run is not None
        infos: dict[str, dict[str, Any]] = {a: {} for a in self.agents}
        refused: dict[str, int] = {}
        asked = list(run.asked)
        for agent in self.agents:
            action = actions.get(agent, CONTINUE)
            why = run.choose(agent, action) if agent in asked else run.refusal(agent, action)
            if why is not None:
                infos[agent]["refused"] = why
                refused[agent] = 1
        progress = run.advance(refused)
        rewards = self.episodes.rewards_of(progress, self.agents)
        terminated, truncated = self.episodes.ended_how()
        observations = self._observations()
        terminations = dict.fromkeys(self.agents, terminated)
        truncations = dict.fromkeys(self.agents, truncated)
        if run.ended:
            assert run.result is not None
            for agent in self.agents:
                infos[agent]["outcome"] = run.result.outcome
            self.agents = []
        return observations, rewards, terminations, truncations, infos
