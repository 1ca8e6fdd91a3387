"""How a leg a straight line cannot take is planned, one planner a way of moving: ``fly``
(OMPL in 3-D round the furniture, kept out of it by the kind's ``keep_out``), ``drive`` (OMPL
in SE2, Reeds-Shepp or Dubins, the body's rectangle at each state's heading) and ``walk`` (A*
on the floor's grid). A kind names its planner in its record
(:attr:`astralis_des.kinds.KindDefaults.planner`); the navigator looks it up in ``PLANNERS``.

A new planner is a function registered under a new name::

    @PLANNERS.register("hop")
    def hop(host, leg): ...  # -> (points at the leg's height or None, reason)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from astralis_des.kinds import KindDefaults
from astralis_des.planning.footprint import facing, rectangle_free
from astralis_des.registry import Registry
from astralis_des.world.geometry import FloatArray

if TYPE_CHECKING:
    from astralis_des.mission.spec import PlanningSpec
    from astralis_des.planning.occupancy import GridMap
    from astralis_des.world.model import World

Planned = tuple[FloatArray | None, str]  # the detour (None: none found) and why not


@dataclass(frozen=True)
class Leg:
    """One leg to plan: from ``a`` to ``b`` for a body of ``kind``, within ``[lo, hi]``."""

    kind: KindDefaults
    a: FloatArray
    b: FloatArray
    radius: float  # m: the body and the mission's margin
    lo: FloatArray  # the window the planner may use
    hi: FloatArray
    seed: int


class Host(Protocol):
    """What a planner needs of the navigator: the world, the mission's planning settings and
    what stands in the way."""

    world: World
    cfg: PlanningSpec

    @property
    def rim_clearance(self) -> float: ...

    def furniture(self, lo: FloatArray, hi: FloatArray) -> FloatArray: ...

    def checker(self, boxes: FloatArray, radius: float,
                keep_out: float = 0.0) -> Callable[[FloatArray], np.ndarray]: ...

    def floor_grid(self, lo: FloatArray, hi: FloatArray, floor: float) -> GridMap: ...


Planner = Callable[[Host, Leg], Planned]
PLANNERS: Registry[str, Planner] = Registry("planner")


@PLANNERS.register("fly")
def fly(host: Host, leg: Leg) -> Planned:
    """OMPL in 3-D, up to a metre above and below the leg, clear of the voxel map and of the
    furniture grown by the body and its keep-out."""
    from astralis_des.planning.ompl_adapter import plan_3d

    a, b, lo, hi = leg.a, leg.b, leg.lo.copy(), leg.hi.copy()
    lo[2], hi[2] = min(a[2], b[2]) - 1.0, max(a[2], b[2]) + 1.0
    keep_out = leg.kind.keep_out
    valid = host.checker(host.furniture(lo - keep_out, hi + keep_out), leg.radius, keep_out)
    plan = plan_3d(valid, lo, hi, a, b, budget=host.cfg.budget, planner=host.cfg.uav_planner,
                   seed=leg.seed, resolution=0.1)
    return (plan.path if plan.ok else None), plan.reason


@PLANNERS.register("drive")
def drive(host: Host, leg: Leg) -> Planned:
    """OMPL in SE2 on the floor's grid, setting off and arriving facing along the leg (or the
    nearest heading that fits); a body with a footprint checked as its rectangle."""
    from astralis_des.planning.ompl_adapter import plan_se2

    a, b = leg.a, leg.b
    grid = host.floor_grid(leg.lo[:2], leg.hi[:2], host.world.floor_below(a))
    heading = math.atan2(b[1] - a[1], b[0] - a[0])
    footprint = leg.kind.footprint
    if footprint is not None:  # the body's rectangle at each state's heading
        clearance = host.rim_clearance

        def valid(states: FloatArray) -> np.ndarray:
            return rectangle_free(grid, states, footprint, clearance)
    else:
        def valid(states: FloatArray) -> np.ndarray:
            return np.asarray(grid.free(states[:, :2], leg.radius))
    start = facing(valid, np.array([a[0], a[1], heading]))
    goal = facing(valid, np.array([b[0], b[1], heading]))
    plan = plan_se2(valid, leg.lo[:2], leg.hi[:2], start, goal,
                    turning_radius=host.cfg.turning_radius, budget=host.cfg.budget,
                    space=host.cfg.ugv_space, seed=leg.seed, resolution=0.05)
    if not plan.ok or plan.path is None:
        return None, plan.reason
    return _on_floor(plan.path[:, :2], a), ""


@PLANNERS.register("walk")
def walk(host: Host, leg: Leg) -> Planned:
    """A* on the floor's grid, the body a disc."""
    from astralis_des.planning.grid import plan_grid

    grid = host.floor_grid(leg.lo[:2], leg.hi[:2], host.world.floor_below(leg.a))
    found, reason = plan_grid(grid, leg.a, leg.b, leg.radius, budget=host.cfg.budget)
    if found is None:
        return None, reason
    return _on_floor(found, leg.a), ""


def _on_floor(xy: FloatArray, a: FloatArray) -> FloatArray:
    """Points in the plane put at the height of the leg's start."""
    return np.column_stack([xy, np.full(len(xy), a[2])])
