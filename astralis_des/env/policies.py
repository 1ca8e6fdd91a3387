"""Policies to run through the environments: a random one, and the paper's heuristics.

``HeuristicPolicy("mixed")`` is the paper's mixed heuristic as a policy: while a round's
searches are under way an asked robot waits (the paper's rounds wait for all of them); then
the robots asked match the open rooms by Eq. 1 (the minimum-cost full matching) and each takes
its room with Table IV's action. Run through :class:`~astralis_des.env.MissionEnv`, it
reproduces ``astralis run``'s event log (with ``label="mixed"``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from astralis_des.assignment import assign
from astralis_des.env.layout import CONTINUE, WAIT
from astralis_des.streams import stream


def random_policy(observation: dict[str, Any], rng: np.random.Generator) -> int:
    """A uniformly drawn action among those the mask allows (the draw ``rng.choice`` makes,
    without its checks)."""
    allowed = np.asarray(observation["action_mask"]).ravel().nonzero()[0]  # flatnonzero
    return int(allowed[rng.integers(len(allowed))]) if len(allowed) else CONTINUE


class HeuristicPolicy:
    """One of the mission strategies that match agents to rooms (``mixed``, ``naive``,
    ``greedy``, ``hard``, ``random``) as a policy: ``policy(env, agent) -> action``."""

    def __init__(self, strategy: str = "mixed") -> None:
        self.strategy = strategy
        self._key: tuple[Any, ...] | None = None
        self._run: Any = None  # the episode the key is of (an id could be reused after it)
        self._actions: dict[str, int] = {}

    def __call__(self, env: Any, agent: str) -> int:
        run = env.mission_run
        if agent not in run.asked:
            return CONTINUE
        if run.inflight:
            return WAIT
        key = (run.sim.env.now, len(run.sim.log.records), tuple(run.asked),
               tuple(run.offered))
        if run is not self._run or key != self._key:
            self._run, self._key, self._actions = run, key, self._plan(run)
        return self._actions.get(agent, WAIT)

    def _plan(self, run: Any) -> dict[str, int]:
        sim = run.sim
        cfg = sim.mission.spec.assignment
        robots = [sim.robots[a] for a in run.asked]
        agents, infos, weights, reachable = sim.round_inputs(run.offered, robots, sim.tried)
        plan = assign(agents, infos, weights, strategy=self.strategy, solver=cfg.solver,
                      high_risk=cfg.high_risk, high_messiness=cfg.high_messiness,
                      reachable=reachable, options=cfg.options.model_dump(),
                      rng=stream(sim.mission.spec.seed, "assignment", len(sim.rounds) + 1))
        return {p.agent: run.layout.index(p.room, p.action) for p in plan.pairs}


mixed_policy = HeuristicPolicy("mixed")
