"""The hexacopter in PyBullet: hover, steps, limits, yaw, rotor saturation."""

from __future__ import annotations

import math
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest

from astralis_des.mission.spec import PhysicsSpec
from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.hexacopter import Hexacopter, write_urdf
from astralis_des.world.model import World

START = (30.0, 30.0, 1.5)
STILL = (0.0, 0.0, 0.0)


@pytest.fixture()
def craft(world: World) -> Iterator[tuple[PhysicsClient, Hexacopter, PhysicsSpec]]:
    spec = PhysicsSpec()
    client = PhysicsClient(world, spec.dt, spec.rate // spec.control_rate, spec.solver_iterations)
    with tempfile.TemporaryDirectory() as folder:
        urdf = write_urdf(spec.uav, Path(folder))
        yield client, Hexacopter(client, spec.uav, urdf, np.array(START), 1 / spec.control_rate), \
            spec
    client.close()


def fly(client: PhysicsClient, craft: Hexacopter, spec: PhysicsSpec, goal: tuple[float, ...],
        seconds: float, yaw: float = 0.0) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    states = []
    for _ in range(round(seconds * spec.control_rate)):
        craft.control(goal, STILL, yaw)
        client.step()
        pos, rot, vel, _ = craft.state()
        states.append((pos, rot, vel))
    return states


def test_hover_holds_within_5_cm(craft: tuple) -> None:
    """Hovering 5 s, and again after a 1 m/s gust, the craft stays within 5 cm of its spot."""
    client, hexa, spec = craft
    still = fly(client, hexa, spec, START, 5.0)
    assert max(np.linalg.norm(p - START) for p, _, _ in still) < 0.05
    client.call("resetBaseVelocity", hexa.body, [1.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    recovered = fly(client, hexa, spec, START, 6.0)
    assert max(np.linalg.norm(p - START) for p, _, _ in recovered[-3 * spec.control_rate:]) \
        < 0.05


@pytest.mark.parametrize("step", [(2.0, 0.0, 0.0), (0.0, 0.0, 2.0), (-2.0, -3.0, 0.0)])
def test_a_position_step_settles_without_overshoot(craft: tuple, step: tuple) -> None:
    """A 2-3.6 m step overshoots by less than 10% and settles within 5 cm in 5 s."""
    client, hexa, spec = craft
    goal = np.add(START, step)
    distance = float(np.linalg.norm(step))
    states = fly(client, hexa, spec, tuple(goal), 6.0)
    along = [float((p - START) @ np.array(step)) / distance for p, _, _ in states]
    assert max(along) < 1.10 * distance
    settled = [np.linalg.norm(p - goal) for p, _, _ in states[5 * spec.control_rate:]]
    assert max(settled) < 0.05


def test_speed_and_tilt_limits_hold_on_a_long_step(craft: tuple) -> None:
    """Sent 15 m away, it never exceeds its speed cap (3 m/s) nor its tilt limit (25 deg)."""
    client, hexa, spec = craft
    states = fly(client, hexa, spec, (45.0, 30.0, 1.5), 10.0)
    speeds = [float(np.linalg.norm(v)) for _, _, v in states]
    tilts = [math.degrees(math.acos(min(1.0, r[2, 2]))) for _, r, _ in states]
    assert max(speeds) <= hexa.max_speed * 1.05
    assert max(tilts) <= spec.uav.max_tilt_deg
    assert max(speeds) > 2.5  # it does fly fast when far


def test_yaw_comes_from_rotor_drag(craft: tuple) -> None:
    """Asked to face 1 rad, it turns there (the only yaw torque is the rotors' drag)."""
    client, hexa, spec = craft
    states = fly(client, hexa, spec, START, 6.0, yaw=1.0)
    rot = states[-1][1]
    assert math.atan2(rot[1, 0], rot[0, 0]) == pytest.approx(1.0, abs=0.02)
    assert np.linalg.norm(states[-1][0] - START) < 0.05


def test_rotor_speeds_stay_within_their_limit(craft: tuple) -> None:
    """However hard it is pushed, no rotor spins faster than max_rotor_speed."""
    client, hexa, spec = craft
    fly(client, hexa, spec, (30.0, 30.0, 30.0), 2.0)
    assert max(hexa.rotor_speed) <= spec.uav.max_rotor_speed + 1e-6


def test_pose_and_velocity_read_once_are_what_pybullet_says_after_each_change(
        craft: tuple) -> None:
    """The client's pose and velocity reads, kept between changes, equal PyBullet's own after
    a reset, a velocity set, a step and a walker-style place: never a stale pose."""
    client, hexa, _ = craft

    def fresh() -> tuple:
        return (pb.getBasePositionAndOrientation(hexa.body, physicsClientId=client.id),
                pb.getBaseVelocity(hexa.body, physicsClientId=client.id))

    def kept() -> tuple:
        return client.base_pose(hexa.body), client.base_velocity(hexa.body)

    assert kept() == fresh()
    client.call("resetBasePositionAndOrientation", hexa.body, [31.0, 30.0, 2.0], [0, 0, 0, 1])
    assert kept() == fresh() and kept()[0][0] == (31.0, 30.0, 2.0)
    client.call("resetBaseVelocity", hexa.body, [0.5, 0.0, 0.0], [0.0, 0.0, 0.1])
    assert kept() == fresh() and kept()[1][0] == (0.5, 0.0, 0.0)
    hexa.control(START, STILL)
    client.step()
    assert kept() == fresh() and kept()[0][0] != (31.0, 30.0, 2.0)
    client.place(hexa.body, [32.0, 30.0, 2.0], (0.0, 0.0, 0.0, 1.0))
    assert kept() == fresh() and kept()[0][0] == (32.0, 30.0, 2.0)
