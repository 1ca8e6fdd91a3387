"""The vehicle lift of a building's stairwell: a platform the UGV drives onto from the
landing, rides to another floor and drives off, in its own shaft at the stairwell's far end
(``Building.lift``; walkers and UAVs keep to the landing and the open well).

The platform is a static box moved by setting its pose (a kinematic body, like the walkers),
and the UGV on it is carried the same way, so it rides without bouncing. Above the ground
floor the shaft has no slab: the platform is the floor the UGV stands on, and it stays at the
floor where the UGV left it. One UGV at a time: a UGV reserves the lift when it comes near
the shaft and frees it when its body has left it. The lift moves only while no other robot is
inside the shaft, and the local layer makes the others wait outside it while it moves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from astralis_des.kinds import KIND_DEFAULTS, KINDS
from astralis_des.physics.client import PhysicsClient
from astralis_des.world.geometry import FloatArray
from astralis_des.world.model import World

THICKNESS = 0.1  # m, the platform's slab
GAP = 0.02  # m between the platform and the floor slab it meets (wheels roll over it)


@dataclass
class Lift:
    """One platform in one column; ``lo``/``hi`` its footprint's corners (x, y)."""

    client: PhysicsClient
    building: str
    lo: FloatArray
    hi: FloatArray
    z: float  # the platform's top: the floor it serves now
    body: int = -1
    rider: str | None = None  # the UGV that holds the reservation
    moving: bool = False
    z_range: tuple[float, float] = field(default=(0.0, 0.0))  # of the ride under way

    def __post_init__(self) -> None:
        size = [*(self.hi - self.lo).tolist(), THICKNESS]
        self.body = self.client.add_box(self._centre(self.z), size)

    def _centre(self, z: float) -> list[float]:
        mid = (self.lo + self.hi) / 2
        return [float(mid[0]), float(mid[1]), z - THICKNESS / 2]

    @property
    def centre(self) -> FloatArray:
        return (self.lo + self.hi) / 2

    @property
    def radius(self) -> float:
        """Half the diagonal of the footprint: the disc the local layer keeps others out of."""
        return float(np.linalg.norm(self.hi - self.lo)) / 2

    def contains(self, xy: FloatArray, margin: float = 0.0) -> bool:
        return bool(np.all(xy[:2] >= self.lo - margin) and np.all(xy[:2] <= self.hi + margin))

    def reserve(self, rider: str) -> bool:
        """Take the lift for ``rider``; false while another UGV holds it."""
        if self.rider in (None, rider):
            self.rider = rider
            return True
        return False

    def release(self, rider: str) -> None:
        if self.rider == rider:
            self.rider = None
            self.moving = False

    def move_towards(self, z: float, step: float) -> bool:
        """Move the platform up to ``step`` towards level ``z``; true once it is there."""
        if abs(z - self.z) <= 1e-9:
            self.moving = False
            return True
        self.moving = True
        self.z_range = (min(self.z, z) - 0.2, max(self.z, z) + 2.0)
        self.z = z if abs(z - self.z) <= step else self.z + math.copysign(step, z - self.z)
        self.client.call("resetBasePositionAndOrientation", self.body, self._centre(self.z),
                         [0.0, 0.0, 0.0, 1.0])
        return False


def lifts_of(world: World, client: PhysicsClient) -> list[Lift]:
    """A lift in the shaft of each building whose stairs a kind that takes the lift (the
    UGV) may use."""
    return [Lift(client, b.id, np.array(b.lift.lo[:2]) + GAP, np.array(b.lift.hi[:2]) - GAP,
                 z=float(b.footprint.lo[2]))
            for b in world.buildings.values()
            if b.lift is not None and any(KIND_DEFAULTS[k].floors == "lift"
                                          for k in world.stairs_passable_by.get(b.id, KINDS))]
