"""Camera, lidar and IMU on PyBullet bodies: geometry, occlusion, ranges, noise, determinism."""

from __future__ import annotations

import logging
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest

from astralis_des.mission.spec import PhysicsSpec
from astralis_des.physics.client import GRAVITY, PhysicsClient
from astralis_des.physics.hexacopter import Hexacopter, write_urdf
from astralis_des.physics.husky import Husky
from astralis_des.physics.sensors import Camera, Imu, Intrinsics, Lidar2D
from astralis_des.world.model import World

SPOT = np.array([30.0, 30.0, 1.5])  # empty outdoors: nothing within 30 m at this height
CORRIDOR = np.array([72.0, 78.25, 0.5])  # building A, ground floor, between two doors
K = Intrinsics(320, 240, 60.0)


@pytest.fixture()
def client(physics_client: PhysicsClient) -> PhysicsClient:
    return physics_client


def robot(client: PhysicsClient, at: np.ndarray) -> int:
    """A 0.4 m box standing in for a robot's body."""
    return client.add_box(at, (0.4, 0.4, 0.4))


def test_intrinsics_follow_the_pinhole_model() -> None:
    """fy = (H/2)/tan(fov/2) = fx; the optical axis lands on (W/2, H/2); x right, y down."""
    assert K.fy == pytest.approx(120 / np.tan(np.radians(30)))
    assert K.fx == K.fy
    uv = K.project(np.array([[0.0, 0.0, 4.0], [1.0, 1.0, 4.0]]))
    assert uv[0] == pytest.approx([160.0, 120.0])
    assert uv[1] == pytest.approx([160.0 + K.fx / 4, 120.0 + K.fy / 4])


def test_a_cube_ahead_lands_where_the_intrinsics_say(client: PhysicsClient) -> None:
    """A 1 m cube 5 m ahead, 0.2 m up: its near face's centroid within 0.5 px of its projection
    (1.5 px of the cube centre's), width fx/4.5, depth 4.5 m, area (fx/4.5)²."""
    camera = Camera(client, robot(client, SPOT), K)
    cube = client.add_box(SPOT + (5.0, 0.0, 0.2), (1.0, 1.0, 1.0))
    frame = camera.capture(time=2.5)
    centroid = frame.uv_of(cube).mean(axis=0)
    face, centre = K.project(np.array([[0.0, -0.2, 4.5], [0.0, -0.2, 5.0]]))  # up is -y
    assert np.hypot(*(centroid - face)) < 0.5
    assert np.hypot(*(centroid - centre)) < 1.5
    rows, cols = np.nonzero(frame.segmentation == cube)
    assert cols.max() - cols.min() + 1 == pytest.approx(K.fx / 4.5, rel=0.05)
    assert float(np.median(frame.depth[rows, cols])) == pytest.approx(4.5, abs=0.03)
    assert frame.pixels_of(cube) == pytest.approx((K.fx / 4.5) ** 2, rel=0.10)
    assert frame.time == 2.5 and frame.rgb.shape == (240, 320, 3)


def test_points_of_lie_on_the_visible_face(client: PhysicsClient) -> None:
    """Back-projected points of the cube lie on its near face x = 34.5 m, within its extent."""
    camera = Camera(client, robot(client, SPOT), K)
    cube = client.add_box(SPOT + (5.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    points = camera.capture().points_of(cube)
    assert len(points) > 1500
    assert np.abs(points[:, 0] - 34.5).max() < 0.05
    assert np.abs(points[:, 1:] - SPOT[1:]).max() < 0.55


def test_a_hidden_box_is_not_in_the_segmentation(client: PhysicsClient) -> None:
    """A box behind another shows no pixels; moved aside, the front one reveals it."""
    camera = Camera(client, robot(client, SPOT), K)
    front = client.add_box(SPOT + (5.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    back = client.add_box(SPOT + (8.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    assert camera.capture().pixels_of(back) == 0
    assert camera.capture().pixels_of(front) > 1500
    client.call("resetBasePositionAndOrientation", front, [30.0, 40.0, 1.5], [0, 0, 0, 1])
    assert camera.capture().pixels_of(back) == pytest.approx((K.fx / 7.5) ** 2, rel=0.15)


def test_a_down_looking_camera_sees_the_floor_box_at_its_depth(client: PhysicsClient) -> None:
    """Pitch 90 at 3 m: a 0.5 m tall box below is 2.5 m away, centred; the image's top points
    along the body's x, its left along the body's y."""
    camera = Camera(client, robot(client, np.array([30.0, 30.0, 3.0])), K, pitch_deg=90.0)
    floor_box = client.add_box((30.0, 30.0, 0.25), (1.0, 1.0, 0.5))
    ahead = client.add_box((31.5, 30.0, 0.1), (0.3, 0.3, 0.2))
    left = client.add_box((30.0, 31.5, 0.1), (0.3, 0.3, 0.2))
    frame = camera.capture()
    rows, cols = np.nonzero(frame.segmentation == floor_box)
    assert float(np.median(frame.depth[rows, cols])) == pytest.approx(2.5, abs=0.03)
    assert np.hypot(*(frame.uv_of(floor_box).mean(axis=0) - (160, 120))) < 0.5
    u, v = frame.uv_of(ahead).mean(axis=0)
    assert u == pytest.approx(160, abs=0.5) and v == pytest.approx(120 - K.fy * 1.5 / 2.9, abs=1)
    u, v = frame.uv_of(left).mean(axis=0)
    assert u == pytest.approx(160 - K.fx * 1.5 / 2.9, abs=1) and v == pytest.approx(120, abs=0.5)
    assert np.isfinite(frame.depth).all()  # the ground fills the rest


def test_the_camera_never_sees_its_own_body(client: PhysicsClient) -> None:
    """Mounted inside a Husky, the camera sees past it; its body stays visible to others."""
    husky = Husky(client, np.array([30.0, 30.0, 0.0]))
    client.step(30)
    target = client.add_box((35.0, 30.0, 0.5), (1.0, 1.0, 1.0))
    inside = Camera(client, husky.body, K, mount=(0.0, 0.0, 0.3))
    frame = inside.capture()
    assert frame.pixels_of(husky.body) == 0 and frame.pixels_of(target) > 1000
    onlooker = Camera(client, robot(client, np.array([26.0, 30.0, 1.0])), K)
    before = onlooker.capture()
    inside.capture()
    after = onlooker.capture()
    assert before.pixels_of(husky.body) > 500
    assert np.array_equal(before.rgb, after.rgb)  # colours restored exactly


def test_segmentation_holds_body_ids_for_every_link(client: PhysicsClient) -> None:
    """A Husky's wheel links read as the Husky's own id; empty sky reads -1, depth inf."""
    husky = Husky(client, np.array([34.0, 30.0, 0.0]))
    frame = Camera(client, robot(client, np.array([31.0, 30.0, 1.0])), K,
                   pitch_deg=10.0).capture()
    ids = set(np.unique(frame.segmentation).tolist())
    assert ids == {-1, client.ground, husky.body}
    assert np.isinf(frame.depth[frame.segmentation == -1]).all()


def test_lidar_ranges_to_a_wall_match_its_distance(client: PhysicsClient) -> None:
    """Without noise the wall 4 m ahead (face at 3.9 m) reads 3.9 m within 3 cm."""
    body = robot(client, SPOT)
    client.add_box(SPOT + (4.0, 0.0, 0.0), (0.2, 4.0, 2.0))
    scan = Lidar2D(client, body, noise_std=0.0).scan()
    ahead = int(np.argmin(np.abs(scan.angles)))
    assert scan.ranges[ahead] == pytest.approx(3.9, abs=0.03)
    assert scan.points[ahead] == pytest.approx(SPOT + (3.9, 0.0, 0.0), abs=0.03)
    assert np.isinf(scan.ranges[np.abs(scan.angles) > np.pi / 2]).all()


def test_lidar_reads_beyond_its_first_pass(client: PhysicsClient) -> None:
    """A scan casts to 5 m, then on for the beams that found nothing: a wall 12 m ahead
    (face at 11.9 m) and one 2 m behind (face at 1.9 m) both read right; the far wall's
    ids are its body's."""
    body = robot(client, SPOT)
    far = client.add_box(SPOT + (12.0, 0.0, 0.0), (0.2, 4.0, 2.0))
    client.add_box(SPOT - (2.0, 0.0, 0.0), (0.2, 4.0, 2.0))
    scan = Lidar2D(client, body, noise_std=0.0).scan()
    ahead = int(np.argmin(np.abs(scan.angles)))
    behind = int(np.argmin(np.abs(np.abs(scan.angles) - np.pi)))
    assert scan.ranges[ahead] == pytest.approx(11.9, abs=0.03) and scan.hit_ids[ahead] == far
    assert scan.ranges[behind] == pytest.approx(1.9, abs=0.03)
    assert Lidar2D(client, body, noise_std=0.0, near=30.0).scan().ranges == pytest.approx(
        scan.ranges, abs=1e-4, nan_ok=True)


def bullet_scan(client: PhysicsClient, lidar: Lidar2D) -> tuple[np.ndarray, np.ndarray]:
    """The scan as one full-length ``rayTestBatch`` against every body: ranges and ids."""
    centre, directions = lidar._frame()
    hits = client.call("rayTestBatch", (centre + lidar.start_offset * directions).tolist(),
                       (centre + lidar.range_max * directions).tolist())
    ids = np.array([h[0] for h in hits])
    ranges = lidar.start_offset + np.array([h[2] for h in hits]) * (
        lidar.range_max - lidar.start_offset)
    ranges[ids < 0] = np.inf
    return ranges, ids


def test_the_planar_scan_reads_what_bullet_reads(client: PhysicsClient) -> None:
    """Walls and furniture in numpy, the other bodies in Bullet: at 60 seeded places in and
    around building A, near a Husky and a walker-sized box, every beam names the body a
    full-length Bullet ray names (bar grazing hits on a box's very corner, which Bullet misses:
    at most 0.1% of beams) and reads its range within 1 cm (Bullet's own error is ~5 mm)."""
    husky = Husky(client, np.array([74.0, 78.25, 0.0]))
    client.step(30)
    walker = client.add_box((70.0, 78.5, 0.9), (0.5, 0.5, 1.8))
    rng = np.random.default_rng(3)
    differ = beams = 0
    seen: set[int] = set()
    for _ in range(60):
        at = np.array([rng.uniform(60.0, 115.0), rng.uniform(65.0, 95.0), rng.uniform(0.3, 3.0)])
        body = robot(client, at)
        lidar = Lidar2D(client, body, noise_std=0.0)
        scan, (ranges, ids) = lidar.scan(), bullet_scan(client, lidar)
        same = scan.hit_ids == ids
        differ += int((~same).sum())
        beams += len(ids)
        both = same & (ids >= 0)
        assert scan.ranges[both] == pytest.approx(ranges[both], abs=0.01)
        seen |= set(scan.hit_ids[both].tolist())
        client.call("removeBody", body)
    assert differ <= beams // 1000
    assert {husky.body, walker} <= seen and len(seen & set(client.static)) >= 4


def test_lidar_beams_turn_with_the_heading(client: PhysicsClient) -> None:
    """Turned 90 deg left, the wall that was ahead is at angle -90 deg (on the right)."""
    body = robot(client, SPOT)
    client.add_box(SPOT + (4.0, 0.0, 0.0), (0.2, 4.0, 2.0))
    client.call("resetBasePositionAndOrientation", body, SPOT.tolist(),
                [0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)])
    scan = Lidar2D(client, body, noise_std=0.0).scan()
    right = int(np.argmin(np.abs(scan.angles + np.pi / 2)))
    assert scan.ranges[right] == pytest.approx(3.9, abs=0.03)


def test_no_return_reads_inf_nan_and_minus_one(client: PhysicsClient) -> None:
    """Outdoors at (30, 30), nothing within 30 m: every beam reads inf, nan, -1."""
    scan = Lidar2D(client, robot(client, SPOT), noise_std=0.0).scan()
    assert np.isinf(scan.ranges).all() and np.isnan(scan.points).all()
    assert (scan.hit_ids == -1).all() and len(scan.ranges) == 360


def test_lidar_noise_has_its_std_and_a_seed_repeats_it(client: PhysicsClient) -> None:
    """200 scans of a wall scatter with std 0.01 m; the same seed gives the same scans."""
    body = robot(client, SPOT)
    client.add_box(SPOT + (4.0, 0.0, 0.0), (0.2, 4.0, 2.0))

    def scans(seed: int) -> np.ndarray:
        lidar = Lidar2D(client, body, noise_std=0.01, rng=np.random.default_rng(seed))
        return np.array([lidar.scan().ranges for _ in range(200)])

    a = scans(7)
    ahead = np.abs(np.linspace(-np.pi, np.pi, 360, endpoint=False)) < 0.3
    assert np.std(a[:, ahead], axis=0).mean() == pytest.approx(0.01, rel=0.1)
    assert np.array_equal(a, scans(7))
    assert not np.array_equal(a, scans(8))


def test_lidar_needs_an_explicit_generator_for_noise(client: PhysicsClient) -> None:
    """Noise without a generator is refused: the global RNG would break determinism."""
    with pytest.raises(ValueError, match=r"no rng: pass a numpy\.random\.Generator"):
        Lidar2D(client, robot(client, SPOT))


def test_lidar_never_hits_its_own_husky(client: PhysicsClient,
                                        caplog: pytest.LogCaptureFixture) -> None:
    """Rays starting 0.6 m out never hit the Husky; from its centre they do, with a warning."""
    husky = Husky(client, np.array([30.0, 30.0, 0.0]))
    client.step(30)
    outside = Lidar2D(client, husky.body, mount=(0.0, 0.0, 0.1), noise_std=0.0,
                      start_offset=0.6).scan()
    assert husky.body not in outside.hit_ids
    with caplog.at_level(logging.WARNING):
        inside = Lidar2D(client, husky.body, mount=(0.0, 0.0, 0.1), noise_std=0.0,
                         start_offset=0.0).scan()
    assert husky.body in inside.hit_ids
    assert "may start inside it" in caplog.text


def test_every_solid_of_the_world_is_in_the_client(client: PhysicsClient,
                                                   world: World) -> None:
    """Every solid above the ground is a collision shape (PyBullet keeps 16 per compound, so
    they go in chunks); the ground floors' slabs are the ground plane itself."""
    shapes = sum(len(client.call("getCollisionShapeData", body, -1)) for body in client.static)
    above = [s for s in world.solids if s.box.hi[2] > 0]
    assert shapes == len(above) == len(world.solids) - len(world.buildings)


def test_corridor_walls_are_at_its_half_width(client: PhysicsClient) -> None:
    """In building A's corridor between doors, walls are 1.15 m left and right; at a door
    (x 70) the side beams pass into the rooms and end at their back walls (8.15 m)."""
    body = robot(client, CORRIDOR)
    scan = Lidar2D(client, body, noise_std=0.0).scan()
    left, right = (int(np.argmin(np.abs(scan.angles - a))) for a in (np.pi / 2, -np.pi / 2))
    assert scan.ranges[left] == pytest.approx(1.15, abs=0.05)
    assert scan.ranges[right] == pytest.approx(1.15, abs=0.05)
    assert scan.hit_ids[left] != body and scan.hit_ids[left] >= 0
    client.call("resetBasePositionAndOrientation", body, [70.0, 78.25, 0.5], [0, 0, 0, 1])
    at_door = Lidar2D(client, body, noise_std=0.0).scan()
    assert at_door.ranges[left] == pytest.approx(79.5 + 7.0 - 0.1 - 78.25, abs=0.05)
    assert at_door.ranges[right] == pytest.approx(78.25 - 70.1, abs=0.05)


@pytest.fixture()
def hover(client: PhysicsClient) -> Iterator[tuple[PhysicsClient, Hexacopter, int]]:
    spec = PhysicsSpec()
    with tempfile.TemporaryDirectory() as folder:
        craft = Hexacopter(client, spec.uav, write_urdf(spec.uav, Path(folder)), SPOT,
                           1 / spec.control_rate)
        yield client, craft, spec.control_rate


def test_a_hovering_hexacopter_feels_one_g_up_and_no_rotation(hover: tuple) -> None:
    """After 3 s of hover the IMU reads +9.81 m/s² on z within 0.1, rates near 0."""
    client, craft, rate = hover
    imu = Imu(client, craft.body)
    readings = []
    for step in range(4 * rate):
        craft.control(SPOT, (0.0, 0.0, 0.0))
        client.step()
        readings.append(imu.read(1 / rate, time=step / rate))
    settled = readings[3 * rate:]
    force = np.array([r.specific_force for r in settled])
    rates = np.array([r.angular_rate for r in settled])
    assert force[:, 2].mean() == pytest.approx(GRAVITY, abs=0.1)
    assert np.abs(force[:, :2].mean(axis=0)).max() < 0.1
    assert np.abs(rates).max() < 0.01
    assert settled[-1].time == pytest.approx((4 * rate - 1) / rate)


def test_a_falling_body_feels_no_force(client: PhysicsClient) -> None:
    """In free fall the IMU reads 0 after its first reading (which assumes no acceleration)."""
    shape = client.call("createCollisionShape", pb.GEOM_BOX, halfExtents=[0.2, 0.2, 0.2])
    body = client.call("createMultiBody", 1.0, shape, basePosition=[30.0, 30.0, 50.0])
    client.call("changeDynamics", body, -1, linearDamping=0.0, angularDamping=0.0)
    imu = Imu(client, body)
    first = imu.read(1 / 60)
    readings = []
    for _ in range(30):
        client.step()
        readings.append(imu.read(1 / 60).specific_force)
    assert first.specific_force == pytest.approx([0.0, 0.0, GRAVITY])
    assert np.abs(readings).max() < 1e-6


def test_imu_bias_shifts_its_reading(client: PhysicsClient) -> None:
    """A body at rest reads (0, 0, 9.81); a bias of (0.1, 0, 0) reads (0.1, 0, 9.81)."""
    body = robot(client, SPOT)
    plain = Imu(client, body).read(0.01)
    biased = Imu(client, body, accel_bias=(0.1, 0.0, 0.0), gyro_bias=(0.0, 0.0, 0.02)).read(0.01)
    assert plain.specific_force == pytest.approx([0.0, 0.0, GRAVITY])
    assert biased.specific_force == pytest.approx([0.1, 0.0, GRAVITY])
    assert biased.angular_rate == pytest.approx([0.0, 0.0, 0.02])


def test_imu_noise_has_its_std_and_a_seed_repeats_it(client: PhysicsClient) -> None:
    """2000 readings scatter with the given stds; the same seed gives identical readings."""
    body = robot(client, SPOT)

    def readings(seed: int) -> np.ndarray:
        imu = Imu(client, body, accel_std=0.05, gyro_std=0.002, rng=np.random.default_rng(seed))
        return np.array([np.concatenate([(r := imu.read(0.01)).specific_force, r.angular_rate])
                         for _ in range(2000)])

    a = readings(3)
    assert np.std(a[:, :3], axis=0) == pytest.approx([0.05] * 3, rel=0.1)
    assert np.std(a[:, 3:], axis=0) == pytest.approx([0.002] * 3, rel=0.1)
    assert np.array_equal(a, readings(3))
