"""An idle Husky may sleep in Bullet (``physics.sleep_idle``): still once settled, woken to go."""

from __future__ import annotations

import numpy as np

from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.husky import REST_Z, Husky
from astralis_des.world.model import World

START = np.array([20.0, 20.0, 0.0])  # empty outdoors


def pose(client: PhysicsClient, husky: Husky) -> tuple:
    return client.call("getBasePositionAndOrientation", husky.body)


def settled(world: World, sleeps: bool) -> tuple[PhysicsClient, Husky]:
    """A Husky set down and left to rest for 4 s (sleeping takes 2 s of stillness)."""
    client = PhysicsClient(world, 1 / 240, 4, 20)
    husky = Husky(client, START, sleeps=sleeps)
    husky.rest()
    client.step(240)
    return client, husky


def test_a_resting_husky_that_may_sleep_stands_bit_for_bit_still(world: World) -> None:
    """Asleep, its pose does not change in the last digit over 2 s of stepping."""
    client, husky = settled(world, sleeps=True)
    before = pose(client, husky)
    client.step(120)
    assert pose(client, husky) == before
    client.close()


def test_a_sleeping_husky_drives_when_woken(world: World) -> None:
    """Woken and driven along a 3 m path, it gets there."""
    client, husky = settled(world, sleeps=True)
    husky.wake()
    husky.follow(np.array([START, START + [3.0, 0.0, 0.0]]), 1.0)
    ticks = 0
    while not husky.track() and ticks < 60 * 15:
        client.step()
        ticks += 1
    end = husky.position()
    client.close()
    assert np.linalg.norm(end[:2] - (START[:2] + [3.0, 0.0])) < 0.3


def test_a_woken_husky_answers_to_what_moves_it(world: World) -> None:
    """Put 5 cm up while asleep, it stays there; woken, it comes down onto its wheels."""
    client, husky = settled(world, sleeps=True)
    (x, y, z), quat = pose(client, husky)
    client.call("resetBasePositionAndOrientation", husky.body, [x, y, z + 0.05], quat)
    client.step(30)
    assert pose(client, husky)[0][2] > z + 0.04
    husky.wake()
    client.step(60)
    assert abs(pose(client, husky)[0][2] - REST_Z) < 0.01
    client.close()


def test_a_husky_that_may_not_sleep_ignores_rest(world: World) -> None:
    """Without ``sleeps`` (the default), resting changes nothing: it stays awake."""
    client, husky = settled(world, sleeps=False)
    (x, y, z), quat = pose(client, husky)
    client.call("resetBasePositionAndOrientation", husky.body, [x, y, z + 0.05], quat)
    client.step(60)
    assert abs(pose(client, husky)[0][2] - REST_Z) < 0.01
    client.close()
