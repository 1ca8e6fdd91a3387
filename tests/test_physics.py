"""The physics fidelity behind the co-simulation contract: missions, consistency with the
kinematic fidelity, determinism, simulations side by side, idle time, failures."""

from __future__ import annotations

import gc
import itertools
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from astralis_des import Mission, RunResult, Simulation, load_mission
from astralis_des.kernel.robot import Motion

MISSIONS = Path(__file__).resolve().parents[1] / "missions"


def physics(name: str, **changes: object) -> Mission:
    return load_mission(MISSIONS / f"{name}.yaml").with_changes(fidelity="physics", **changes)


def jsonl(result: RunResult) -> str:
    return "\n".join(json.dumps(e, separators=(",", ":")) for e in result.events)


@pytest.fixture(scope="module")
def fig7_physics() -> RunResult:
    return Simulation(physics("fig7")).run()


@pytest.mark.parametrize("path", sorted(MISSIONS.glob("*.yaml")), ids=lambda p: p.stem)
def test_every_mission_runs_in_physics(path: Path) -> None:
    """Each mission runs in physics too (up to 150 s) and ends with a proper outcome."""
    mission = load_mission(path)
    limit = min(mission.spec.time_limit, 150.0)
    shifted = [e.model_dump() for e in mission.spec.timeline if e.at <= limit]
    result = Simulation(mission.with_changes(fidelity="physics", time_limit=limit,
                                             timeline=shifted)).run()
    assert result.fidelity == "physics"
    assert result.outcome in {"found", "not_found", "time_limit", "team_lost"}
    assert result.events[-1]["kind"] == "mission_end"
    assert sum(s.distance for s in result.robots.values()) > 10.0


def test_fig7_matches_the_kinematic_fidelity(fig7_physics: RunResult) -> None:
    """Same assignment, same rooms in the same order, same finder; completed actions last
    within 20% of their kinematic duration (or 1 s, for actions of a second or two)."""
    kinematic = Simulation(load_mission(MISSIONS / "fig7.yaml")).run()
    assert [r["matching"] for r in fig7_physics.rounds] == [
        [{**m, "cost": pytest.approx(m["cost"], abs=0.05)} for m in r["matching"]]
        for r in kinematic.rounds]
    assert fig7_physics.found_by == kinematic.found_by == "uav2"

    def durations(result: RunResult) -> dict[int, float]:
        start = {e["task"]: e["t"] for e in result.events if e["kind"] == "task_started"}
        return {e["task"]: e["t"] - start[e["task"]] for e in result.events
                if e["kind"] == "task_finished" and e["status"] == "succeeded"
                and e["action"] != "land"}  # (from where each fidelity was at the end)

    slow, fast = durations(fig7_physics), durations(kinematic)
    # every action done in kinematic fidelity is done in physics too (the physics run may
    # finish one more before its later detection)
    assert set(fast) <= set(slow) and len(fast) >= 4
    for task, seconds in fast.items():
        assert abs(slow[task] - seconds) < max(0.2 * seconds, 1.0), (task, seconds, slow[task])
    # When the target is seen may differ more: in physics the UAVs hold for the patrolling
    # bystanders of the cluttered rooms (the local layer), which the kinematic model ignores.
    assert fig7_physics.time_to_find is not None


def test_the_same_seed_gives_the_same_event_log(fig7_physics: RunResult) -> None:
    """A physics run is reproducible to the byte."""
    again = Simulation(physics("fig7")).run()
    assert jsonl(again) == jsonl(fig7_physics)


def test_two_simulations_side_by_side_do_not_disturb_each_other(
        fig7_physics: RunResult) -> None:
    """Two physics simulations advanced in turns, 0.5 s at a time, each give the solo log."""
    a, b = Simulation(physics("fig7")), Simulation(physics("fig7", seed=8))
    solo_b = jsonl(Simulation(physics("fig7", seed=8)).run())
    for t in itertools.count(0.5, 0.5):
        done_a, done_b = a.advance(t), b.advance(t)
        if done_a and done_b:
            break
    assert jsonl(a.finish()) == jsonl(fig7_physics)
    assert jsonl(b.finish()) == solo_b


def test_idle_time_costs_no_physics_steps() -> None:
    """Waiting 10 minutes before round 1 takes as many physics steps as not waiting, give or
    take a control tick (times 600 s later round differently, which can move an arrival by a
    tick), against the 144,000 steps that stepping through the wait would take. Rooms are left
    empty: patrolling bystanders would be elsewhere on their loops 10 min later."""
    plain = Simulation(physics("fig7", scene={"clutter": False}))
    plain.run()
    waited = Simulation(physics("fig7", assignment={"search": ["A.1.1"], "start_at": 600.0},
                                time_limit=1200.0, scene={"clutter": False}))
    result = waited.run()
    assert result.time_to_find is not None and result.time_to_find > 600.0
    tick = round(plain.cosim.period / plain.cosim.client.dt)  # physics steps a control tick
    assert abs(waited.cosim.client.steps - plain.cosim.client.steps) <= tick


def run_motion(sim: Simulation, robot_id: str, points: list[tuple[float, float, float]],
               seconds: float) -> object:
    """Send one motion to the co-simulation directly; return its outcome."""
    robot = sim.robots[robot_id]
    outcome: list[object] = []

    def go():  # type: ignore[no-untyped-def]
        result = yield sim.cosim.execute(robot, Motion(np.array(points), robot.speed,
                                                       accel=robot.accel))
        outcome.append(result)

    sim.env.process(go())
    sim.env.run(until=seconds)
    return outcome[0] if outcome else None


def test_a_robot_pushing_into_a_wall_is_stuck_and_the_contact_is_an_event() -> None:
    """A UAV sent through a wall presses on it: a contact event, then 'stuck' after 2 s."""
    sim = Simulation(physics("fig7", physics={"stuck_timeout": 2.0}))
    start = sim.robots["uav1"].pose
    outcome = run_motion(sim, "uav1", [tuple(start), (78.0, 80.0, 1.5)], 30.0)
    assert outcome is not None and not outcome.ok  # type: ignore[attr-defined]
    assert outcome.reason == "stuck: no progress for 2 s"  # type: ignore[attr-defined]
    contacts = sim.log.of_kind("contact")
    assert contacts and contacts[0]["robot"] == "uav1" and contacts[0]["other"] == "wall"


def test_a_robot_leaving_the_world_fails_its_motion() -> None:
    """A UAV flown off the site ends its motion with 'left the world', not a crash."""
    sim = Simulation(physics("fig7"))
    start = sim.robots["uav2"].pose
    outcome = run_motion(sim, "uav2", [tuple(start), (start[0], 190.0, 1.5)], 120.0)
    assert outcome is not None and outcome.reason == "left the world"  # type: ignore[attr-defined]


def test_a_nan_state_fails_the_motion(monkeypatch: pytest.MonkeyPatch) -> None:
    """If the physics state turns to NaN the motion fails with that reason."""
    sim = Simulation(physics("fig7"))
    driver = sim.cosim.drivers["uav1"]
    monkeypatch.setattr(driver, "position", lambda: np.full(3, np.nan))
    start = sim.robots["uav1"].pose
    outcome = run_motion(sim, "uav1", [tuple(start), (86.0, 70.0, 1.5)], 5.0)
    assert outcome is not None and "NaN" in outcome.reason  # type: ignore[attr-defined]


def test_a_simulation_never_finished_leaves_no_folder_behind() -> None:
    """The UAV model is written to a temporary folder per physics simulation: removed when
    the run ends, and also when a simulation that never ran or never ended is let go (or the
    process exits): a notebook's abandoned runs leave nothing in /tmp."""
    sim = Simulation(physics("fig7"))
    folder = sim.cosim._folder
    assert (folder / "hexacopter.urdf").is_file()
    del sim
    gc.collect()
    assert not folder.exists()
    probe = ("import sys; from pathlib import Path; from astralis_des import Simulation, "
             "load_mission; sim = Simulation(load_mission(Path(sys.argv[1])).with_changes("
             "fidelity='physics')); print(sim.cosim._folder)")
    done = subprocess.run([sys.executable, "-c", probe, str(MISSIONS / "fig7.yaml")],
                          capture_output=True, text=True, timeout=120, check=True)
    assert not Path(done.stdout.strip()).exists()  # at the process's exit
