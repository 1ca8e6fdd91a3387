"""What the physics pieces (the local layer, making way, perception) see of the physics
co-simulation that runs them: a ``Protocol``, so they import nothing above them
(``astralis_des.cosim.physics`` implements it and wires them)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    import numpy as np

    from astralis_des.kernel.robot import Robot
    from astralis_des.physics.client import PhysicsClient
    from astralis_des.physics.drivers import Driver
    from astralis_des.physics.lift import Lift
    from astralis_des.world.geometry import FloatArray
    from astralis_des.world.model import World
    from astralis_des.world.scene import Mover


class Engine(Protocol):
    """The running physics co-simulation."""

    world: World
    client: PhysicsClient
    robots: dict[str, Robot]
    drivers: dict[str, Driver]
    active: dict[str, tuple[Robot, Any, Any]]  # robot id -> (robot, its track, done event)
    lifts: list[Lift]
    period: float  # s: one control period

    @property
    def movers(self) -> list[tuple[Mover, int]]: ...  # scripted movers and their bodies
    @property
    def t(self) -> float: ...  # physics time: whole control periods

    def fits(self, rid: str, points: FloatArray) -> np.ndarray: ...
    def stands(self, rid: str, points: FloatArray) -> np.ndarray: ...
    def may_ask(self, rid: str) -> bool: ...
    def target_now(self, now: float) -> tuple[int, FloatArray, FloatArray]: ...
