"""The 3-D lidar: its returns are where full-length Bullet rays hit, on the body they hit."""

from __future__ import annotations

import numpy as np
import pytest

from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.lidar3d import Lidar3D
from astralis_des.world.model import World

RAY_BATCH = 4000  # rays a rayTestBatch call takes at once


@pytest.fixture(scope="module")
def client(world: World) -> PhysicsClient:
    return PhysicsClient(world, 1 / 240, 1, 50)


def bullet(client: PhysicsClient, centre: np.ndarray, dirs: np.ndarray, start: float,
           reach: float) -> tuple[np.ndarray, np.ndarray]:
    """Bullet alone: every ray its full length; ranges (inf: none) and body ids."""
    hits = []
    for i in range(0, len(dirs), RAY_BATCH):
        part = dirs[i:i + RAY_BATCH]
        hits += client.call("rayTestBatch", (centre + start * part).tolist(),
                            (centre + reach * part).tolist())
    ids = np.array([h[0] for h in hits])
    ranges = np.where(ids >= 0, start + np.array([h[2] for h in hits]) * (reach - start),
                      np.inf)
    return ranges, ids


@pytest.mark.parametrize("where", ["street", "corridor", "second_floor_room"])
def test_returns_lie_where_bullet_rays_hit(client: PhysicsClient, world: World,
                                           where: str) -> None:
    """16 x 1,800 beams from the street, building A's ground-floor corridor and a room of
    its second floor (another robot's box beside it): the same beams return as with Bullet
    alone, within its collision margin (5 mm), and on the same body (ties at shared faces
    aside: 99.9%)."""
    corridor = world.spaces["A.1.corridor"].box
    room = world.rooms["A.2.1.2"].box
    at = {"street": (90.0, 60.0, 1.0),
          "corridor": (*corridor.center[:2], corridor.lo[2] + 1.2),
          "second_floor_room": (*room.center[:2], room.lo[2] + 1.5)}[where]
    box = client.call("createCollisionShape", 3, halfExtents=[0.2, 0.2, 0.1])
    body = client.call("createMultiBody", 0, box, basePosition=list(at))
    other = client.call("createMultiBody", 0, box, basePosition=[at[0] + 2.0, at[1], at[2]])
    try:
        lidar = Lidar3D(client, body, noise_std=0.0)
        scan = lidar.scan()
        centre, heading = lidar.pose()
        dirs = lidar.directions(heading).reshape(-1, 3)
        ranges, ids = bullet(client, centre, dirs, lidar.start, lidar.range_max)
        ours = scan.ranges.ravel()
        assert np.array_equal(np.isfinite(ours), np.isfinite(ranges))
        both = np.isfinite(ours)
        assert both.sum() > 10_000
        assert np.abs(ours[both] - ranges[both]).max() < 0.005
        assert (scan.hit_ids.ravel()[both] == ids[both]).mean() > 0.999
        assert other in set(scan.hit_ids.ravel().tolist())  # a body, through Bullet
        points = scan.points.reshape(-1, 3)[both]
        assert np.allclose(points, centre + ranges[both, None] * dirs[both], atol=0.005)
    finally:
        client.call("removeBody", other)
        client.call("removeBody", body)
