"""The human avatar: a capsule body moved kinematically along its path at walking speed, so
that it collides with robots and is seen by sensors like any body."""

from __future__ import annotations

import numpy as np

from astralis_des.physics.client import PhysicsClient
from astralis_des.world.geometry import FloatArray

RADIUS = 0.25
HEIGHT = 1.2  # between the caps: 1.7 m tall in all


class Walker:
    """A person's capsule, placed (not pushed) where its driver says (each control period)."""

    centre_height = RADIUS + HEIGHT / 2  # m from the floor to its centre

    def __init__(self, client: PhysicsClient, centre: FloatArray) -> None:
        self.client = client
        shape = client.call("createCollisionShape", 7, radius=RADIUS, height=HEIGHT)  # capsule
        self.body = int(client.call("createMultiBody", 0, shape,
                                    basePosition=[float(v) for v in centre]))

    def place(self, centre: FloatArray, yaw: float = 0.0) -> None:
        """Put it at ``centre`` (a capsule: upright whichever way it faces)."""
        self.client.place(self.body, [float(v) for v in centre], (0.0, 0.0, 0.0, 1.0))

    def position(self) -> FloatArray:
        pos, _ = self.client.base_pose(self.body)
        return np.array(pos)
