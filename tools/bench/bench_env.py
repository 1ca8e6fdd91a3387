"""Environment benchmark: decisions per second through ``astralis_des.env``, and the env's
overhead over the kernel running the same decisions itself.

    python tools/bench/bench_env.py [--episodes 40] [--physics 2] [--cpu]

- *random*: ``MissionEnv.step`` with a random valid action (from the mask), observation
  building included, kinematic fidelity, default team; episodes over different seeds, and the
  same seed again and again (what a learner on one scenario sees: the world's caches warm).
  Goal (issue 43): >= 2,000 decisions/s. The steps' wall time is split, in the same run, into
  the kernel's (SimPy, the actions, sensing, the landing at the end: what the decisions set
  going), the env's own (observations, masks, rounds, rewards, selection) and the policy's;
  ``env/kernel`` is their ratio, and ``kernel-bound`` the decisions/s if the env cost
  nothing; ``end s`` is the kernel's part spent ending episodes (the UAVs land). ``reset s``
  (a new run to its first decision) is apart, as the issue measured. ``--cpu`` times this
  process's CPU time instead of the wall's (others benchmarking on the same cores).
  ``gc s``: Python's garbage collections while stepping (inside the other parts).
- *overhead*: the mixed heuristic as a policy through the env against ``Simulation.run`` with
  the mixed strategy, the same missions (the env reproduces the run's event log byte for
  byte): wall time of one over the other. Goal (issue 22): at most 1.3x.
- *physics*: decisions per second and simulated seconds per wall second, random policy.
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.env import MissionEnv, mixed_policy, random_policy  # noqa: E402
from astralis_des.env.run import EpisodeRun  # noqa: E402
from astralis_des.mission.loader import load_mission  # noqa: E402
from astralis_des.simulation import Simulation  # noqa: E402

DEFAULT = ROOT / "missions" / "urban_search.yaml"


class Clock:
    """Wall seconds by part, while stepping: ``kernel`` (the run between decisions, less the
    env's rounds inside it), ``env_inside`` (the env's rounds: who may take what, asking,
    committing, booking), ``policy``, ``reset`` and ``end`` (ending runs, in ``kernel``);
    ``gc``: the garbage collector's passes, wherever they fell."""

    def __init__(self) -> None:
        self.now = time.perf_counter  # or time.process_time (--cpu)
        self.zero()
        self._gc_start = 0.0
        gc.callbacks.append(self._collecting)

    def zero(self) -> None:
        self.kernel = self.env_inside = self.policy = self.reset = self.end = self.gc = 0.0

    def _collecting(self, phase: str, info: dict[str, Any]) -> None:
        if phase == "start":
            self._gc_start = self.now()
        else:
            self.gc += self.now() - self._gc_start


CLOCK = Clock()
_run = EpisodeRun._run


def _timed_run(self: EpisodeRun) -> None:
    t0, inside = CLOCK.now(), CLOCK.env_inside
    _run(self)
    CLOCK.kernel += CLOCK.now() - t0 - (CLOCK.env_inside - inside)


def _env_side(method: Callable[..., Any]) -> Callable[..., Any]:
    def timed(self: EpisodeRun, *args: Any) -> Any:
        t0 = CLOCK.now()
        try:
            return method(self, *args)
        finally:
            CLOCK.env_inside += CLOCK.now() - t0
    return timed


_finish = Simulation.finish


def _timed_finish(self: Simulation) -> Any:
    t0 = CLOCK.now()
    try:
        return _finish(self)
    finally:
        CLOCK.end += CLOCK.now() - t0


EpisodeRun._run = _timed_run  # type: ignore[method-assign]
Simulation.finish = _timed_finish  # type: ignore[method-assign]
for _name in ("_who_may", "_open", "_commit", "_book"):
    setattr(EpisodeRun, _name, _env_side(getattr(EpisodeRun, _name)))


def episodes(env: MissionEnv, seeds: list[int], policy: str) -> tuple[int, float, float]:
    """``(decisions, wall s of the steps, simulated s)`` over one episode per seed; the split
    in ``CLOCK``."""
    rng = np.random.default_rng(0)
    decisions, wall, simulated = 0, 0.0, 0.0
    CLOCK.zero()
    for seed in seeds:
        kept = CLOCK.kernel, CLOCK.env_inside, CLOCK.end
        t0 = CLOCK.now()
        env.reset(seed=seed)  # its run to the first decision counts as the reset's
        t1 = CLOCK.now()
        CLOCK.reset += t1 - t0
        CLOCK.kernel, CLOCK.env_inside, CLOCK.end = kept
        for agent in env.agent_iter():
            obs, _, term, trunc, _ = env.last()
            if term or trunc:
                env.step(None)
                continue
            p0 = CLOCK.now()
            action = random_policy(obs, rng) if policy == "random" else mixed_policy(env, agent)
            CLOCK.policy += CLOCK.now() - p0
            env.step(action)
            decisions += 1
        wall += CLOCK.now() - t1
        simulated += env.mission_run.sim.env.now
    return decisions, wall, simulated


def kernel(seeds: list[int]) -> float:
    """Wall s of ``Simulation.run`` (mixed strategy, no outputs) over the seeds."""
    base = load_mission(DEFAULT)
    wall = 0.0
    for seed in seeds:
        mission = base.with_changes(seed=seed)
        t0 = CLOCK.now()
        Simulation(mission).run()
        wall += CLOCK.now() - t0
    return wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--episodes", type=int, default=40)
    parser.add_argument("--physics", type=int, default=2, help="physics episodes (0: none)")
    parser.add_argument("--cpu", action="store_true",
                        help="this process's CPU time instead of wall time (a shared machine)")
    args = parser.parse_args()
    if args.cpu:
        CLOCK.now = time.process_time
    seeds = list(range(1, args.episodes + 1))
    env = MissionEnv(DEFAULT)
    episodes(env, [1000], "random")  # imports, the world's first caches
    print("Goal (issue 43): random policy >= 2,000 decisions/s")
    print(f"{'kinematic, default team':34} {'decisions':>9} {'cpu s' if args.cpu else 'wall s':>7} "
          f"{'decisions/s':>11}"
          f"   {'kernel s':>8} {'env s':>6} {'policy s':>8} {'env/kernel':>10}"
          f" {'kernel-bound':>12} {'end s':>5} {'reset s':>7} {'gc s':>5}")
    for label, these in (("random, a new seed each episode", seeds),
                         ("random, one seed again and again", [7] * args.episodes)):
        n, wall, _ = episodes(env, these, "random")
        own = wall - CLOCK.kernel - CLOCK.policy
        print(f"{label:34} {n:9,} {wall:7.2f} {n / wall:11,.0f}   {CLOCK.kernel:8.2f} "
              f"{own:6.2f} {CLOCK.policy:8.2f} {own / CLOCK.kernel:10.3f} "
              f"{n / CLOCK.kernel:12,.0f} {CLOCK.end:5.2f} {CLOCK.reset:7.2f} {CLOCK.gc:5.2f}")
    mixed = MissionEnv(DEFAULT, label="mixed")
    kernel(seeds)  # both warm: the world's caches hold these missions' rooms
    episodes(mixed, seeds, "mixed")
    t_kernel = kernel(seeds)
    n, t_env, _ = episodes(mixed, seeds, "mixed")
    print(f"\nmixed heuristic, {len(seeds)} missions: kernel alone {t_kernel:.2f} s, through the "
          f"env {t_env:.2f} s ({n:,} decisions): overhead {t_env / t_kernel:.2f}x")
    if args.physics:
        env = MissionEnv(DEFAULT, fidelity="physics", time_limit=120.0)
        n, wall, simulated = episodes(env, list(range(1, args.physics + 1)), "random")
        env.close()
        print(f"\nphysics, random policy, {args.physics} episodes of at most 120 s: {n} decisions "
              f"in {wall:.1f} s: {n / wall:.1f} decisions/s, {simulated / wall:.1f} simulated "
              f"s per wall s")


if __name__ == "__main__":
    main()
