"""What both environments share: the mission, the spaces, episodes and their rewards."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import spaces

from astralis_des import compiled
from astralis_des.env.layout import Layout
from astralis_des.env.observe import Observer, observation_space, state_space
from astralis_des.env.rewards import Progress, RewardFn, RewardWeights
from astralis_des.env.run import EpisodeRun
from astralis_des.mission.loader import Mission, load_mission
from astralis_des.simulation.timeline import groups


class Episodes:
    """The mission, its action layout and spaces, and the run of the current episode.

    ``mission``: a :class:`Mission` or a mission file. ``fidelity`` and ``time_limit`` replace
    the mission's. ``reward``: ``(progress, agent) -> float`` (default :class:`RewardWeights`).
    ``label``: the strategy name the rounds are logged under (``env``; a policy that replays a
    heuristic may give its name). ``hold_s``: how long ``hold`` lasts. ``out_dir``: each
    episode writes its event log, summary and recording to ``out_dir/episode_NNNN``.
    """

    def __init__(self, mission: Mission | str | Path, *, fidelity: str | None = None,
                 time_limit: float | None = None, reward: RewardFn | None = None,
                 label: str = "env", hold_s: float = 10.0,
                 out_dir: str | Path | None = None) -> None:
        base = mission if isinstance(mission, Mission) else load_mission(mission)
        changes: dict[str, Any] = {}
        if fidelity is not None:
            changes["fidelity"] = fidelity
        if time_limit is not None:
            changes["time_limit"] = time_limit
        self.mission = base.with_changes(**changes) if changes else base
        self.reward: RewardFn = reward if reward is not None else RewardWeights()
        self.label, self.hold_s = label, float(hold_s)
        self.out_dir = Path(out_dir) if out_dir is not None else None
        self.possible_agents: list[str] = [m.id for m in self.mission.spec.team]
        self.layout = Layout(tuple(r for _, rooms in groups(self.mission) for r in rooms))
        n, r = len(self.possible_agents), len(self.layout.rooms)
        self.observation_spaces = {a: observation_space(n, r, self.layout.size)
                                   for a in self.possible_agents}
        self.action_spaces = {a: spaces.Discrete(self.layout.size)
                              for a in self.possible_agents}
        self.state_space = state_space(n, r)
        self.episode = 0
        self.run: EpisodeRun | None = None
        self.observer: Observer | None = None
        self._seed: int | None = None
        self._draws: np.random.Generator | None = None

    def observation_space(self, agent: str) -> spaces.Space[Any]:
        return self.observation_spaces[agent]

    def action_space(self, agent: str) -> spaces.Space[Any]:
        return self.action_spaces[agent]

    def start(self, seed: int | None) -> None:
        """A new episode: the mission with ``seed`` (given), else the mission's own seed the
        first time and then seeds drawn from it, one per episode."""
        self.close_run()
        if seed is not None:
            self._draws = np.random.default_rng(seed)
            episode_seed = int(seed)
        elif self._draws is None:
            episode_seed = int(self.mission.spec.seed)
            self._draws = np.random.default_rng(episode_seed)
        else:
            episode_seed = int(self._draws.integers(2**31 - 1))
        self._seed = episode_seed
        self.episode += 1
        if self.episode == compiled.MANY:  # a training run: numba's import repays from here
            compiled.enable()  # (the same episodes, bit for bit; without numba, numpy's path)
        mission = (self.mission if episode_seed == self.mission.spec.seed
                   else self.mission.with_changes(seed=episode_seed))
        out = self.out_dir / f"episode_{self.episode:04d}" if self.out_dir else None
        self.run = EpisodeRun(mission, self.layout, label=self.label, hold_s=self.hold_s,
                              out_dir=out)
        self.observer = Observer(self.run)

    @property
    def seed(self) -> int | None:
        """The mission seed of the current episode."""
        return self._seed

    def rewards_of(self, progress: Progress, agents: list[str]) -> dict[str, float]:
        return {a: float(self.reward(progress, a)) for a in agents}

    def ended_how(self) -> tuple[bool, bool]:
        """``(terminated, truncated)``: found, searched out or the team lost, against out of
        simulated time."""
        run = self.run
        if run is None or run.result is None:
            return False, False
        out = run.result.outcome
        return out != "time_limit", out == "time_limit"

    def close_run(self) -> None:
        if self.run is not None:
            self.run.close()



class Front:
    """What both environment classes show of their :class:`Episodes` (the spaces, the
    episode's run, the state, rendering and closing): put before the PettingZoo base."""

    episodes: Episodes

    def _open(self, mission: Mission | str | Path, **options: Any) -> None:
        self.episodes = Episodes(mission, **options)
        self.possible_agents = list(self.episodes.possible_agents)
        self.observation_spaces = self.episodes.observation_spaces
        self.action_spaces = self.episodes.action_spaces
        self.state_space = self.episodes.state_space
        self.agents: list[str] = []
        self.render_mode = None

    def observation_space(self, agent: str) -> Any:
        return self.episodes.observation_space(agent)

    def action_space(self, agent: str) -> Any:
        return self.episodes.action_space(agent)

    @property
    def mission_run(self) -> Any:
        """The current episode's :class:`~astralis_des.env.run.EpisodeRun` (its ``sim`` is the
        :class:`~astralis_des.simulation.Simulation`)."""
        return self.episodes.run

    def state(self) -> np.ndarray:
        assert self.episodes.observer is not None
        return self.episodes.observer.state()

    def render(self) -> None:
        """Nothing to draw here: the episode's recording (``out_dir``) is for Rerun."""
        return None

    def close(self) -> None:
        self.episodes.close_run()
