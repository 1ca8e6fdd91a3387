"""astralis_des.env: the PettingZoo environments over the mission kernel."""

from __future__ import annotations

import contextlib
import io
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("pettingzoo")

from pettingzoo.test import api_test, parallel_api_test, parallel_seed_test, seed_test

from astralis_des.cli import main
from astralis_des.env import (
    CONTINUE,
    HOLD,
    WAIT,
    MissionEnv,
    ParallelMissionEnv,
    RewardWeights,
    mixed_policy,
    random_policy,
)
from astralis_des.simulation.metrics import search_time

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "missions" / "urban_search.yaml"
FIDELITIES = {"kinematic": {}, "physics": {"fidelity": "physics", "time_limit": 20.0}}


def _quietly(check: Callable[..., None], *args: Any, **kwargs: Any) -> None:
    """PettingZoo's checks print and warn (agent names, Dict spaces): what they assert stays."""
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("ignore")
        check(*args, **kwargs)


@pytest.mark.parametrize("fidelity", FIDELITIES)
def test_pettingzoo_api_tests_pass(fidelity: str) -> None:
    kw = FIDELITIES[fidelity]
    cycles = 200 if fidelity == "kinematic" else 15
    _quietly(api_test, MissionEnv(DEFAULT, **kw), num_cycles=cycles)
    _quietly(parallel_api_test, ParallelMissionEnv(DEFAULT, **kw), num_cycles=cycles)


@pytest.mark.parametrize("fidelity", FIDELITIES)
def test_pettingzoo_seed_tests_pass(fidelity: str) -> None:
    kw = FIDELITIES[fidelity]
    cycles = 50 if fidelity == "kinematic" else 8
    _quietly(seed_test, lambda: MissionEnv(DEFAULT, **kw), num_cycles=cycles)
    _quietly(parallel_seed_test, lambda: ParallelMissionEnv(DEFAULT, **kw), num_cycles=cycles)


def _play(env: MissionEnv, policy: Callable[[MissionEnv, str, Any], int | None]
          ) -> dict[str, float]:
    """One episode; each agent's return."""
    returns: dict[str, float] = dict.fromkeys(env.possible_agents, 0.0)
    for agent in env.agent_iter():
        obs, reward, term, trunc, _ = env.last()
        returns[agent] += reward
        env.step(None if term or trunc else policy(env, agent, obs))
    return returns


@pytest.mark.parametrize(("name", "fidelity"), [
    ("urban_search", "kinematic"), ("fig7", "kinematic"), ("autzen_recon", "kinematic"),
    ("urban_search", "physics")])
def test_the_mixed_heuristic_through_the_env_logs_what_astralis_run_logs(
        name: str, fidelity: str, tmp_path: Path) -> None:
    """Byte for byte. (Not ``faults``: there a timeline command keeps the UGV busy at a round,
    and the paper's round queues a room behind the command, where the env asks only the free.)
    """
    path = ROOT / "missions" / f"{name}.yaml"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(path), "--fidelity", fidelity,
                     "--out", str(tmp_path / "run")]) == 0
    env = MissionEnv(path, fidelity=fidelity, label="mixed", out_dir=tmp_path / "env")
    env.reset()
    _play(env, lambda e, a, _: mixed_policy(e, a))
    env.close()
    ran = (tmp_path / "run" / "events.jsonl").read_bytes()
    assert (tmp_path / "env" / "episode_0001" / "events.jsonl").read_bytes() == ran


def test_the_default_label_names_the_env_as_the_strategy(tmp_path: Path) -> None:
    env = MissionEnv(DEFAULT, out_dir=tmp_path)
    env.reset()
    _play(env, lambda e, a, _: mixed_policy(e, a))
    rounds = env.mission_run.sim.log.of_kind("assignment")
    assert rounds and {r["strategy"] for r in rounds} == {"env"}


def _random_log(seed: int, tmp: Path, policy_seed: int = 3) -> bytes:
    env = MissionEnv(DEFAULT, out_dir=tmp)
    env.reset(seed=seed)
    rng = np.random.default_rng(policy_seed)
    _play(env, lambda e, a, obs: random_policy(obs, rng))
    env.close()
    return (tmp / "episode_0001" / "events.jsonl").read_bytes()


def test_reset_with_a_seed_is_reproducible_byte_for_byte(tmp_path: Path) -> None:
    first = _random_log(5, tmp_path / "a")
    assert first == _random_log(5, tmp_path / "b")
    assert first != _random_log(6, tmp_path / "c")


def test_a_busy_agent_is_never_asked_and_time_only_moves_on() -> None:
    env = MissionEnv(DEFAULT)
    env.reset(seed=2)
    rng = np.random.default_rng(0)
    last_t = 0.0
    for agent in env.agent_iter():
        obs, _, term, trunc, _ = env.last()
        if term or trunc:
            env.step(None)
            continue
        run = env.mission_run
        handler = run.sim.handler(agent)
        assert handler.current is None and not handler.queued  # free: nothing to do
        assert run.sim.env.now >= last_t
        last_t = run.sim.env.now
        assert obs["action_mask"][CONTINUE] == 0 and obs["action_mask"][WAIT] == 1
        env.step(random_policy(obs, rng))


def test_agents_free_at_the_same_time_are_asked_in_team_order() -> None:
    env = MissionEnv(DEFAULT)
    env.reset()
    asked = []
    while env.mission_run.sim.env.now == 0.0 and env.agents:
        asked.append(env.agent_selection)
        env.step(WAIT)
    assert asked == ["uav1", "uav2", "ugv1", "op1"]  # everyone free at the start


def test_invalid_actions_are_refused_with_a_reason_not_an_exception() -> None:
    env = MissionEnv(DEFAULT)
    env.reset()
    layout = env.episodes.layout
    env.step(10**6)  # uav1: not an action
    assert "not an action index" in env.infos["uav1"]["refused"]
    env.step(layout.index("A.1.1.1", "inspect"))  # uav2: a person's search
    assert env.infos["uav2"]["refused"] == "a uav has no inspect"
    env.step(layout.index("A.2.1.1", "observe_corridor"))  # ugv1: a later segment
    assert "not open now" in env.infos["ugv1"]["refused"]
    env.step(CONTINUE)  # op1: free, so continue means nothing
    assert env.infos["op1"]["refused"] == "continue: only for an agent that is busy"
    # all four refused: they wait, and each paid the refusal weight
    assert env.mission_run.sim.log.of_kind("assignment") == []


def test_two_agents_picking_one_room_in_parallel_the_first_takes_it() -> None:
    env = ParallelMissionEnv(DEFAULT)
    obs, _ = env.reset()
    layout = env.episodes.layout
    room = layout.index("A.1.1.1", "spiral_inward")
    actions = {"uav1": room, "uav2": room, "ugv1": WAIT, "op1": WAIT}
    obs, rewards, _, _, infos = env.step(actions)
    assert infos["uav2"]["refused"].endswith("taken by another agent at this decision time")
    assert "refused" not in infos["uav1"]
    first = env.mission_run.sim.log.of_kind("assignment")[0]
    assert first["matching"] == [{"agent": "uav1", "room": "A.1.1.1", "action": "spiral_inward",
                                  "cost": first["matching"][0]["cost"]}]
    assert rewards["uav2"] == pytest.approx(rewards["uav1"] - 1.0)  # the refusal weight
    busy = next(a for a in env.agents if a == "uav1")
    assert obs[busy]["action_mask"].tolist() == [1] + [0] * (layout.size - 1)


def test_hold_hovers_a_uav_and_stands_a_person_still() -> None:
    env = MissionEnv(DEFAULT, hold_s=7.0)
    env.reset()
    for _ in range(4):
        env.step(HOLD)
    sim = env.mission_run.sim
    hovers = [r for r in sim.log.of_kind("task_queued") if r["action"] == "hover"]
    assert [r["robot"] for r in hovers] == ["uav1", "uav2"]
    assert sim.env.now == pytest.approx(7.0)  # the holds end: the two on foot asked
    assert env.mission_run.asked == ["ugv1", "op1"]
    for _ in range(2):
        env.step(HOLD)
    assert sim.env.now == pytest.approx(9.405)  # the UAVs took off (2.405 s), hovered 7 s
    assert env.mission_run.asked == ["uav1", "uav2"]


def test_the_default_reward_adds_up_to_the_missions_figures() -> None:
    env = MissionEnv(DEFAULT)
    env.reset()
    returns = _play(env, lambda e, a, _: mixed_policy(e, a))
    sim, result = env.mission_run.sim, env.mission_run.result
    cfg = sim.mission.spec.assignment
    risk = search_time(sim, "human", {r for r, s in sim.rooms.items() if s.risk >= cfg.high_risk})
    mess = search_time(sim, "ugv",
                       {r for r, s in sim.rooms.items() if s.messiness >= cfg.high_messiness})
    failed = sum(st.tasks_failed for st in result.robots.values())
    w = RewardWeights()
    expected = w.found * result.found - w.time * result.end_time - w.human_risk * risk \
        - w.ugv_clutter * mess - w.failure * failed
    assert result.found
    for agent in env.possible_agents:
        assert returns[agent] == pytest.approx(expected, abs=1e-6)


def test_a_reward_function_of_ones_own() -> None:
    env = ParallelMissionEnv(DEFAULT, reward=lambda progress, agent: progress.dt)
    env.reset()
    total = 0.0
    while env.agents:
        actions = {a: mixed_policy(env, a) for a in env.agents}
        _, rewards, _, _, _ = env.step(actions)
        total += rewards["op1"]
    assert total == pytest.approx(env.mission_run.sim.env.now)


def test_observations_say_what_the_mission_knows() -> None:
    env = MissionEnv(DEFAULT)
    env.reset()
    obs = env.observe("uav1")["observation"]
    sim = env.mission_run.sim
    layout = env.episodes.layout
    assert obs["me"].tolist() == [1, 0, 0, 0]
    assert obs["agents"][0, :3].tolist() == [1, 0, 0]  # a UAV
    assert obs["agents"][3, :3].tolist() == [0, 0, 1]  # the person
    first = layout.room_index["A.1.1.1"]
    assert obs["rooms"][first, 1] == 1.0  # open now
    assert obs["rooms"][layout.room_index["A.2.1.1"], 0] == 1.0  # a later segment
    assert obs["rooms"][first, 6] == pytest.approx(sim.rooms["A.1.1.1"].risk)
    assert env.state().shape == env.state_space.shape
    assert env.observation_space("uav1").contains(env.observe("uav1"))


def test_the_heuristic_policy_follows_each_episode(tmp_path: Path) -> None:
    """Episode after episode (new seeds: other risks, other rooms), the policy plans for the
    episode at hand: each reproduces the kernel's own run of that seed."""
    from astralis_des.mission.loader import load_mission
    from astralis_des.simulation import Simulation

    env = MissionEnv(DEFAULT, label="mixed", out_dir=tmp_path / "env")
    for episode, seed in enumerate((1, 2, 3), start=1):
        env.reset(seed=seed)
        _play(env, lambda e, a, _: mixed_policy(e, a))
        Simulation(load_mission(DEFAULT).with_changes(seed=seed),
                   out_dir=tmp_path / f"run{seed}").run()
        ran = (tmp_path / f"run{seed}" / "events.jsonl").read_bytes()
        assert (tmp_path / "env" / f"episode_{episode:04d}" / "events.jsonl").read_bytes() == ran
    env.close()


def test_the_random_policy_draws_what_rng_choice_draws() -> None:
    """The same actions from the same generator as ``rng.choice`` of the allowed, one to many,
    and the generator left in the same state (an experiment's draws stay the same)."""
    ours, theirs = np.random.default_rng(5), np.random.default_rng(5)
    for n in [1, 2, 3, 7, 40, 129] * 50:
        mask = np.zeros(129, dtype=np.int8)
        mask[np.random.default_rng(n).choice(129, n, replace=False)] = 1
        assert random_policy({"action_mask": mask}, ours) == int(
            theirs.choice(np.flatnonzero(mask)))
    assert ours.integers(2**62) == theirs.integers(2**62)
    assert random_policy({"action_mask": np.zeros(129, dtype=np.int8)}, ours) == CONTINUE


def test_a_long_training_run_goes_on_on_the_compiled_kernels_with_the_same_episodes() -> None:
    """From its MANY-th episode an env runs compiled (a training run repays numba's import);
    the episode after it observes what the numpy path observes, step for step."""
    from astralis_des import compiled

    pytest.importorskip("numba")
    compiled.disable()
    try:
        env = MissionEnv(DEFAULT)
        for episode in range(1, compiled.MANY):
            env.reset(seed=episode)
            assert compiled.kernels() is None, episode
        env.reset(seed=compiled.MANY)
        assert compiled.kernels() is not None

        def episode_of(seed: int) -> list[Any]:
            env.reset(seed=seed)
            seen, rng = [], np.random.default_rng(0)
            for agent in env.agent_iter():
                obs, reward, term, trunc, _ = env.last()
                seen.append((agent, reward, _plain(obs)))
                env.step(None if term or trunc else random_policy(obs, rng))
            return seen

        fast = episode_of(7)
        compiled.disable()
        assert episode_of(7) == fast
    finally:
        compiled.disable()


def _plain(value: Any) -> Any:
    """An observation as lists and numbers, to compare whole."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return np.asarray(value).tolist()
