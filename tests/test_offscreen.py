"""Robots a camera cannot see are left out of its render: the same frame, their colours kept."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from astralis_des.mission.spec import PhysicsSpec
from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.husky import Husky
from astralis_des.physics.offscreen import Offscreen
from astralis_des.physics.sensors import Camera, Intrinsics
from astralis_des.world.model import World

K = Intrinsics(160, 120, 60.0, far=30.0)
EYE = np.array([30.0, 30.0, 0.0])  # empty outdoors; the camera looks along +x


@pytest.fixture()
def scene(world: World) -> Iterator[tuple[PhysicsClient, int, list[int]]]:
    """A camera body and Huskies ahead, at the frame's edges and behind it."""
    spec = PhysicsSpec()
    client = PhysicsClient(world, spec.dt, spec.rate // spec.control_rate, spec.solver_iterations)
    eye = client.add_box(EYE + [0.0, 0.0, 1.0], (0.2, 0.2, 0.2))
    spots = [(5.0, 0.0), (6.0, 3.6), (6.0, -3.6), (4.0, 3.0), (-4.0, 0.0), (3.0, 8.0)]
    huskies = [Husky(client, EYE + [dx, dy, 0.0]).body for dx, dy in spots]
    client.step(60)
    yield client, eye, huskies
    client.close()


def frames(client: PhysicsClient, eye: int, huskies: list[int]) -> tuple:
    """The same view rendered with every body, and with the unseen ones left out."""
    plain = Camera(client, eye, K).capture()
    culled = Camera(client, eye, K, offscreen=Offscreen(client, huskies)).capture()
    return plain, culled


def test_a_frame_is_the_same_pixel_for_pixel(scene: tuple) -> None:
    """Colour, depth and segmentation match the frame rendered with every body in it."""
    plain, culled = frames(*scene)
    assert np.array_equal(plain.rgb, culled.rgb)
    assert np.array_equal(plain.segmentation, culled.segmentation)
    assert np.array_equal(plain.depth, culled.depth)
    shown = set(np.unique(plain.segmentation).tolist())
    assert scene[2][0] in shown and scene[2][4] not in shown


def test_only_bodies_wholly_outside_the_view_are_left_out(scene: tuple) -> None:
    """The Husky behind the camera and the one far to its side are out; those ahead are in."""
    client, eye, huskies = scene
    offscreen = Offscreen(client, huskies)
    camera = Camera(client, eye, K)
    position, rotation = camera.pose()
    shown = [offscreen._may_show(shape, position, rotation, K) for shape in offscreen.shapes]
    assert shown == [True, True, True, True, False, False]


def test_bodies_left_out_get_their_colours_back(scene: tuple) -> None:
    """A camera looking back sees the Husky behind as it did before the frame that left it
    out (by render: PyBullet reports one colour a link after a change)."""
    client, eye, huskies = scene
    back = client.add_box(EYE + [-1.0, 0.0, 1.0], (0.2, 0.2, 0.2))
    client.call("resetBasePositionAndOrientation", back, (EYE + [-1.0, 0.0, 1.0]).tolist(),
                client.call("getQuaternionFromEuler", [0.0, 0.0, np.pi]))
    before = Camera(client, back, K).capture()
    assert huskies[4] in set(np.unique(before.segmentation).tolist())
    frames(client, eye, huskies)
    after = Camera(client, back, K).capture()
    assert np.array_equal(before.rgb, after.rgb)
