"""The Husky from pybullet_data: non-holonomic, driven through its wheel joints only."""

from __future__ import annotations

import math

import numpy as np

from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.husky import Husky
from astralis_des.world.model import World


def test_lateral_velocity_stays_near_zero_on_a_curve(world: World) -> None:
    """Following a 3 m-radius half circle at up to 1 m/s: sideways speed < 0.15 m/s."""
    client = PhysicsClient(world, 1 / 240, 3, 20)
    husky = Husky(client, np.array([20.0, 20.0, 0.0]))
    client.step(40)
    arc = np.linspace(0.0, math.pi, 60)
    path = np.column_stack([20 + 3 * np.sin(arc), 23 - 3 * np.cos(arc), np.zeros(60)])
    husky.follow(path, 1.0)
    forward, lateral, ticks = [], [], 0
    while not husky.track() and ticks < 80 * 30:
        client.step()
        f, s = husky.velocity_in_body()
        forward.append(f)
        lateral.append(s)
        ticks += 1
    end = husky.position()
    client.close()
    assert max(forward) > 0.8  # it did drive at about its speed
    assert max(abs(s) for s in lateral) < 0.15
    assert np.linalg.norm(end[:2] - path[-1, :2]) < 0.3


def test_wheels_are_the_only_actuators(world: World) -> None:
    """Its four wheel joints are velocity-controlled; nothing else drives it."""
    client = PhysicsClient(world, 1 / 240, 3, 20)
    husky = Husky(client, np.array([20.0, 20.0, 0.0]))
    names = [client.call("getJointInfo", husky.body, j)[1].decode() for j in husky.wheels]
    client.close()
    assert sorted(names) == ["front_left_wheel", "front_right_wheel", "rear_left_wheel",
                             "rear_right_wheel"]


def test_a_sneak_peek_at_every_door_of_building_a_touches_no_wall() -> None:
    """One UGV looks into all 18 rooms of building A in turn, riding the lift between
    floors: every sneak peek succeeds, the robot stops where it can turn on the spot (its
    half-diagonal and a margin from the wall), and its body never touches a wall."""
    from conftest import MISSIONS

    from astralis_des import Simulation, load_mission
    from astralis_des.actions.common import stand_off

    base = load_mission(MISSIONS / "fig7.yaml")
    sim = Simulation(base.with_changes(
        fidelity="physics", team=[{"id": "ugv1", "kind": "ugv", "start": [70.0, 78.25, 0.0]}],
        scene={"clutter": False}, time_limit=5000, target={"room": "B.1.1.1"},
        assignment={**base.spec.assignment.model_dump(), "start_at": 4000.0}))
    robot = sim.robots["ugv1"]
    assert stand_off(robot, 0.5) > 0.61 + 0.05  # the Husky's half-diagonal, and a margin
    sim.start()
    rooms = sorted(r for r in sim.world.rooms if r.startswith("A."))
    assert len(rooms) == 18
    peeks = [sim.enqueue("ugv1", "sneak_peek", room) for room in rooms]
    sim.advance(1500.0)
    results = [p.value for p in peeks if p.triggered]
    assert len(results) == 18 and all(r.ok for r in results), [r.message for r in results]
    assert [e for e in sim.log.records if e["kind"] == "contact"] == []
    sim.finish()
