"""Two policies through the multi-agent environment, their returns compared.

    pip install -e '.[env]'
    python examples/env_policies.py [--episodes 10] [--mission missions/urban_search.yaml]

A random policy (a uniform draw among the actions its mask allows) and the paper's mixed
heuristic as a policy (:class:`astralis_des.env.policies.HeuristicPolicy`) play the same
episodes (one mission seed each); the table gives each one's mean team return, how often it
found the target and how long that took. Nothing is trained: this is the loop a learner would
sit in.
"""

from __future__ import annotations

import argparse
import statistics
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from astralis_des.env import MissionEnv, mixed_policy, random_policy

ROOT = Path(__file__).resolve().parents[1]
Policy = Callable[[MissionEnv, str, dict[str, Any]], int]


def play(env: MissionEnv, policy: Policy, seed: int) -> tuple[float, bool, float]:
    """One episode: the team's return (the first robot's: the reward is shared), whether the
    target was found and when the mission ended."""
    env.reset(seed=seed)
    team_return = 0.0
    for agent in env.agent_iter():
        observation, reward, terminated, truncated, _ = env.last()
        if agent == env.possible_agents[0]:
            team_return += reward
        env.step(None if terminated or truncated else policy(env, agent, observation))
    result = env.mission_run.result
    return team_return, bool(result.found), float(result.end_time)


def compare(mission: Path, episodes: int) -> dict[str, list[tuple[float, bool, float]]]:
    rng = np.random.default_rng(0)
    policies: dict[str, Policy] = {
        "random": lambda env, agent, obs: random_policy(obs, rng),
        "mixed heuristic": lambda env, agent, obs: mixed_policy(env, agent),
    }
    env = MissionEnv(mission)
    return {name: [play(env, policy, seed) for seed in range(1, episodes + 1)]
            for name, policy in policies.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--episodes", type=int, default=10)
    parser.add_argument("--mission", type=Path, default=ROOT / "missions" / "urban_search.yaml")
    args = parser.parse_args()
    print(f"{'policy':16} {'mean return':>12} {'found':>7} {'mean time to end':>17}")
    for name, runs in compare(args.mission, args.episodes).items():
        returns = [r for r, _, _ in runs]
        found = sum(f for _, f, _ in runs)
        print(f"{name:16} {statistics.mean(returns):12.1f} {found:4}/{len(runs):<2} "
              f"{statistics.mean(t for _, _, t in runs):15.1f} s")


if __name__ == "__main__":
    main()
