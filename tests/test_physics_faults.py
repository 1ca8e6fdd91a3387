"""Faults in physics: a robot that crashes is faulted and its room searched by another; a
robot that makes no progress is failed as stuck, however it is pushed about."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from astralis_des import Simulation, load_mission
from astralis_des.kernel.robot import Motion, Robot

MISSIONS = Path(__file__).resolve().parents[1] / "missions"


def fig7_physics(**changes: object) -> Simulation:
    return Simulation(load_mission(MISSIONS / "fig7.yaml").with_changes(fidelity="physics",
                                                                        **changes))


def run_motion(sim: Simulation, robot: Robot, motion: Motion, until: float) -> list[Any]:
    """Send one motion to the co-simulation directly: ``[outcome, end time]`` (empty if it
    has not ended by ``until``)."""
    outcome: list[Any] = []

    def go():  # type: ignore[no-untyped-def]
        outcome.append((yield sim.cosim.execute(robot, motion)))
        outcome.append(sim.env.now)

    sim.env.process(go())
    sim.env.run(until=until)
    return outcome


def test_a_uav_tipped_over_mid_search_is_faulted_and_its_room_searched_by_another() -> None:
    """uav1 is knocked on its side 3 s into its spiral: it fails 'crashed', a fault event
    follows, it takes no more rooms, and its room is searched in the next round by another
    robot, successfully."""
    base = load_mission(MISSIONS / "fig7.yaml").spec
    sim = fig7_physics(target={"room": "A.1.2.2"},  # not found in the first round
                       assignment={**base.assignment.model_dump(), "search": ["A.1.1", "A.1.2"]})
    sim.start()
    while sim.handler("uav1").current is None or sim.handler("uav1").current.action == "move":
        sim.advance(sim.env.now + 0.5)
    room = sim.handler("uav1").current.room
    sim.advance(sim.env.now + 3.0)
    body = sim.cosim.drivers["uav1"].body
    client = sim.cosim.client
    here, _ = client.call("getBasePositionAndOrientation", body)
    client.call("resetBasePositionAndOrientation", body, here,
                client.call("getQuaternionFromEuler", [math.radians(80), 0.0, 0.0]))
    result = sim.run()
    faults = [e for e in result.events if e["kind"] == "fault"]
    assert [(e["robot"], e["reason"].split(":")[0]) for e in faults] == [("uav1", "crashed")]
    failed = [e for e in result.events if e["kind"] == "task_finished" and e["robot"] == "uav1"
              and e["status"] == "failed"]
    assert [e["room"] for e in failed] == [room] and "crashed" in failed[0]["message"]
    assert result.robots["uav1"].faulted
    later = [r for r in result.rounds if r["t"] > faults[0]["t"]]
    assert later and all("uav1" not in r["agents"] for r in later)
    again = [m for r in later for m in r["matching"] if m["room"] == room]
    assert again and again[0]["agent"] != "uav1"
    redone = [e for e in result.events if e["kind"] == "task_finished" and e["room"] == room
              and e["robot"] == again[0]["agent"] and e["action"] != "move"]
    assert redone and redone[-1]["status"] == "succeeded"
    assert room in result.rooms_searched


def test_a_recovered_uav_is_set_upright_and_flies_again() -> None:
    """A crashed UAV recovered by the timeline stands upright over where it fell, at its
    flying height, and takes rooms again."""
    sim = fig7_physics(timeline=[{"at": 20.0, "event": "recover", "robot": "uav1"}])
    sim.start()
    sim.advance(5.0)
    body = sim.cosim.drivers["uav1"].body
    client = sim.cosim.client
    here, _ = client.call("getBasePositionAndOrientation", body)
    client.call("resetBasePositionAndOrientation", body, here,
                client.call("getQuaternionFromEuler", [0.0, math.radians(85), 0.0]))
    sim.advance(21.0)
    assert sim.robots["uav1"].faulted is False
    craft = sim.cosim.drivers["uav1"].craft
    assert craft.tilt_deg() < 1.0
    floor = sim.world.floor_below(craft.position())
    assert abs(craft.position()[2] - (floor + sim.robots["uav1"].height)) < 0.05
    assert [e["kind"] for e in sim.log.records if e.get("robot") == "uav1"
            and e["kind"] in ("fault", "recover")] == ["fault", "recover"]
    sim.finish()


def test_a_robot_pushed_back_and_forth_is_failed_as_stuck_within_its_cap() -> None:
    """A UAV sent through a wall reaches it in about 4 s; from then on it is pushed 0.3 m
    back and forth every second, so it keeps moving but gets no further along its path: it
    fails 'stuck' stuck_timeout (4 s) after it stopped gaining ground, long before its cap
    (2 x 5.4 s + 30 s). Counting displacement instead of progress, it never would."""
    sim = fig7_physics(physics={"stuck_timeout": 4.0})
    robot = sim.robots["uav1"]
    driver = sim.cosim.drivers["uav1"]
    motion = Motion(np.array([robot.pose, (78.0, 80.0, 1.5)]), robot.speed, accel=robot.accel)
    tick = driver.tick

    def pushed(t: float) -> str | None:
        if t > 5.0 and t - int(t) < 0.05:  # a shove at each whole second, alternately
            away = 3.0 if int(t) % 2 else -3.0
            sim.cosim.client.call("resetBaseVelocity", driver.body, [away, 0.0, 0.0],
                                  [0, 0, 0])
        return tick(t)

    driver.tick = pushed
    outcome = run_motion(sim, robot, motion, 60.0)
    assert outcome, "the motion never ended"
    result, ended = outcome
    assert result.reason == "stuck: no progress for 4 s"
    times, points = np.array(robot.trail_t), np.array(robot.trail_p)
    late = points[times > 5.0][:, 0]
    assert np.abs(np.diff(late)).sum() > 0.5  # it was moving about all along
    assert 8.0 < ended < 11.0 < 2 * motion.duration + 30.0
    sim.finish()


def test_a_motion_that_takes_far_longer_than_planned_times_out() -> None:
    """A motion still under way at twice its planned duration plus 30 s ends 'timed out'
    (a UAV kept held by a body that never leaves its lane keeps no progress either: here the
    stuck test is switched off by a long stuck_timeout, so the cap decides)."""
    sim = fig7_physics(physics={"stuck_timeout": 500.0})
    robot = sim.robots["uav1"]
    motion = Motion(np.array([robot.pose, (78.0, 80.0, 1.5)]), robot.speed, accel=robot.accel)
    result, ended = run_motion(sim, robot, motion, 200.0)
    cap = 2 * motion.duration + 30.0
    assert result.reason == f"timed out: not there after {cap:.0f} s"
    assert cap <= ended < cap + 0.5
    sim.finish()
