"""Robots in physics that stood still until their task failed 'stuck' (or could not set off
again), found by the fidelity benchmark in the outcome study's scenarios 30 to 49; each
mechanism with numbers, then the missions themselves."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from test_landing import scenario
from test_local import contacts_between, corridor_mission

from astralis_des.kernel.robot import Motion
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.physics.drivers import ARRIVED
from astralis_des.physics.local import SAMPLE, Body, LocalLayer


def test_a_uav_ducking_through_a_door_does_not_hold_for_a_person_it_will_pass_over() -> None:
    """Scenario 36 (naive): uav1 came through A.2.1.1's door under the lintel (5.31 m, its
    flight height 5.48 m) towards its pattern's first point, 1.5 m in, where the operator
    stood idle (head at 5.25 m). Judged at its height in the doorway the person was in its
    band, so it held there for 15 s, twice. Where its way meets the person it is back at
    5.48 m, over the head: it does not hold."""
    corners = np.array([[66.0, 79.06], [66.0, 80.02], [65.25, 80.51], [64.5, 81.0]])
    legs = [a + np.outer(np.arange(0, np.linalg.norm(b - a), SAMPLE), (b - a) /
                         np.linalg.norm(b - a)) for a, b in itertools.pairwise(corners)]
    route = np.vstack(legs)[:16]
    heights = np.minimum(5.31 + 0.17 * np.arange(16) * SAMPLE / 1.0, 5.48)  # climbing back
    uav = Body("uav1", "uav", route[0], np.array([0.0, 1.0]), (5.21, 5.41),
               KIND_DEFAULTS["uav"].passes_by, 3)
    person = Body("human1", "human", np.array([65.1, 80.6]), np.zeros(2), (3.5, 5.25),
                  KIND_DEFAULTS["human"].passes_by, 10_000)
    forward = np.array([0.0, 1.0])
    right = np.array([1.0, 0.0])
    args = (uav, [person], forward, right, 1.0, route)
    hold, _, _, blockers = LocalLayer._decide(None, *args)  # type: ignore[arg-type]
    assert hold and blockers == [person]  # judged at its height now: the 15 s stall
    hold, _, _, blockers = LocalLayer._decide(None, *args, heights)  # type: ignore[arg-type]
    assert not hold and blockers == []
    low = np.full(16, 5.31)  # a way that stays low would still meet the person: held
    assert LocalLayer._decide(None, *args, low)[0]  # type: ignore[arg-type]


def test_a_walker_held_a_step_from_its_goal_has_arrived() -> None:
    """Scenario 42 (naive): the operator stopped 8 cm short of the door point of A.1.1.1,
    held for the Husky behind it (which made way back and forth five times), and its move
    failed 'stuck'. Held within ARRIVED of its goal, a walker has arrived; held farther
    away, it waits."""
    sim = corridor_mission([{"id": "human1", "kind": "human", "start": [70.0, 78.25, 0.0]}])
    robot = sim.robots["human1"]
    driver = sim.cosim.drivers["human1"]
    path = np.array([[70.0, 78.25, 1.6], [66.0, 78.8, 1.6]])
    for short, expected in ((0.08, "arrived"), (ARRIVED + 0.1, None)):
        motion = Motion(path, robot.speed, accel=robot.accel, turn_rate=robot.turn_rate)
        motion.t0 = 0.0
        driver.start(motion, 0.0)
        while motion.length - driver.progress() > short:
            assert driver.tick(0.0) is None
        driver.held = True
        assert driver.tick(0.0) == expected


def test_a_held_husky_steps_round_a_landed_uav_on_its_way() -> None:
    """Scenario 46 (naive): the Husky's first move went past uav1, landed and idle 1.8 m
    ahead of it (a landed UAV cannot make way). The local layer held it and asked it to
    step round, but a held Husky never turned the step into its reference, so it stayed held
    (15 s, twice, 'stuck'). Now it sets its way round while it waits, and passes without
    touching the UAV."""
    sim = corridor_mission([{"id": "ugv1", "kind": "ugv", "start": [100.22, 91.58, 0.0]},
                            {"id": "uav1", "kind": "uav", "start": [98.49, 91.05, 0.0]}])
    sim.start()
    done = sim.enqueue("ugv1", "move", params={"x": 94.5, "y": 89.8})
    sim.advance(40.0)
    assert done.triggered and done.value.ok, done.value.message
    assert done.value.distance < 8.0  # 6.0 m in a straight line: a short way round
    assert sim.cosim.local.shifts > 0 and not contacts_between(sim, "ugv1", "uav1")
    sim.finish()


def test_a_husky_makes_way_only_to_where_it_can_set_off_from() -> None:
    """Scenario 47 (greedy): the Husky made way to a spot 0.37 m from the corridor's wall
    where its planner's disc fits, but its 1.01 x 0.69 m rectangle fits at no heading; when
    its next move came, its planner found the start in collision ('no path'), twice. A spot
    it makes way to, or is nudged to, must take its rectangle at some heading."""
    sim = corridor_mission([{"id": "ugv1", "kind": "ugv", "start": [70.0, 78.25, 0.0]}])
    husky, nav = sim.robots["ugv1"], sim.navigator
    spot = np.array([[67.567, 78.878, 4.0]])  # where it made way to then
    assert nav.fits(husky, spot)[0] and not nav.stands(husky, spot)[0]
    assert nav.stands(husky, spot - [0.0, 0.2, 0.0])[0]  # 0.2 m farther from the wall
    nudged = nav._nudge(husky, np.array([67.37, 78.903, 4.0]))  # where it stopped then
    assert nudged is not None and nav.stands(husky, nudged[None, :])[0]


@pytest.mark.parametrize(("index", "strategy"), [(18, "naive"), (36, "naive"), (42, "naive"),
                                                 (46, "naive"), (47, "greedy")])
def test_the_missions_that_stalled_in_physics_fail_no_task(index: int, strategy: str) -> None:
    """Each mission the mechanisms above came from (and scenario 18: a Husky by the stairs,
    :func:`test_local.test_a_husky_standing_by_the_stairs_makes_way_along_the_corridor`)
    now runs with no failed task, no fault, and finds the target."""
    result = scenario(index, strategy, "physics").run()
    failed = [f"{e['t']} {e['robot']} {e['action']}: {e['message']}" for e in result.events
              if e["kind"] == "task_finished" and e["status"] == "failed"]
    assert failed == [] and result.outcome == "found"
    assert not [e for e in result.events if e["kind"] == "fault"]
