"""A plug-in that adds a legged ground robot, its own search action, its planner, its physics
body and its look, and a strategy that weighs travel time: everything through the package's
registries, nothing edited in it. A mission names this file (``plugins: [legged.py]``);
``legged_search.yaml`` beside it runs it in both fidelities.

The robot is a quadruped the size of a Boston Dynamics Spot (1.1 x 0.5 m, 0.6 m high at the
body, 1.6 m/s): it takes the stairs like a person, keeps its legs' swing clear of the walls
and searches a room by trotting across it in wide lanes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from astralis_des.action_spec import ActionParams, Number, Verb
from astralis_des.actions.common import (
    ActionGen,
    Context,
    failed,
    plane_to_floor,
    room_of,
    search_path,
)
from astralis_des.assignment.eq1 import Agent, RoomInfo, Weights, distances
from astralis_des.assignment.strategies import register_strategy
from astralis_des.kernel.robot import Robot
from astralis_des.kernel.tasks import Task
from astralis_des.kinds import KIND_DEFAULTS, CameraDefaults, KindDefaults
from astralis_des.physics.client import PhysicsClient
from astralis_des.physics.drivers import DRIVERS, PlacedDriver
from astralis_des.planning.grid import plan_grid
from astralis_des.planning.planners import PLANNERS, Host, Leg, Planned
from astralis_des.plugins import action, robot_kind
from astralis_des.sinks.looks import LOOKS, Color
from astralis_des.world import coverage as cov
from astralis_des.world.geometry import FloatArray

KIND = "legged"
BODY = (0.9, 0.4, 0.25)  # m: the torso, length, width and depth
LEGS = 0.45  # m: from the hips to the feet, standing
SWING = 0.1  # m more it keeps from walls than its disc where there is room: its feet swing

# -- the kind: one record --
robot_kind(KIND, KindDefaults(
    planner="trot", speed=1.6, accel=1.0,
    camera=CameraDefaults(range=None, fov_deg=70.0, pitch_deg=10.0, gimbal=False,
                          look_around=True),
    height=0.7,  # its cameras, on the front of the torso
    distance="manhattan", sensors=("camera", "imu"),
    radius=0.3,  # the disc its planners keep clear of walls: its torso's half-width and more
    passing_radius=0.5, half_width=0.3,  # others pass it by its half-diagonal
    band=(-0.7, 0.1), floors="stairs", label="legged", look="quadruped",
    color=(46, 139, 87), weights="ugv"))  # Eq. 1 reads the UGV's weights unless set


# -- its search action --
class TrotSweepParams(ActionParams):
    spacing: Number = Field(2.5, ge=0.5, le=10.0, description="m between its lanes")


@action("trot_sweep", (KIND,), params=TrotSweepParams, search=True,
        table4=((False, False), (True, False), (False, True), (True, True)),
        verbs=(Verb("sweep", "trot across a room in lanes"),))
def trot_sweep(ctx: Context, robot: Robot, task: Task) -> ActionGen:
    """Trot across the room in lanes ``spacing`` metres apart along its longer side."""
    room = room_of(ctx, task)
    if room is None:
        return failed("trot_sweep needs a room")
    spacing = TrotSweepParams.model_validate(dict(task.params)).spacing
    size = np.subtract(room.box.hi, room.box.lo)
    plane = cov.lawnmower(room.box, spacing, axis=int(size[1] > size[0]))
    plane = cov.start_near(plane, room.box, room.door_point("room"))
    return (yield from search_path(ctx, robot, room, plane_to_floor(room, plane),
                                   "trot_sweep"))


# -- its planner --
@PLANNERS.register("trot")
def trot(host: Host, leg: Leg) -> Planned:
    """A* on the floor's grid with the legs' swing kept clear, then pulled taut: a point is
    dropped wherever the straight line past it stays as clear (a trotting robot goes
    straight, not cell by cell)."""
    grid = host.floor_grid(leg.lo[:2], leg.hi[:2], host.world.floor_below(leg.a))
    clear = leg.radius + SWING
    found, reason = plan_grid(grid, leg.a, leg.b, clear, budget=host.cfg.budget)
    if found is None:  # too tight for the swing: as close as a disc of its body goes
        found, reason = plan_grid(grid, leg.a, leg.b, clear := leg.radius,
                                  budget=host.cfg.budget)
    if found is None:
        return None, reason
    taut = [0]
    while taut[-1] < len(found) - 1:
        i, j = taut[-1], len(found) - 1
        while j > i + 1 and not _straight(grid, found[i], found[j], clear):
            j -= 1
        taut.append(j)
    xy = found[taut]
    return np.column_stack([xy, np.full(len(xy), leg.a[2])]), ""


def _straight(grid: object, a: FloatArray, b: FloatArray, clear: float) -> bool:
    n = max(2, int(np.ceil(np.hypot(*(b[:2] - a[:2])) / 0.05)) + 1)
    points = np.linspace(a[:2], b[:2], n)
    return bool(np.all(grid.free(points, clear)))  # type: ignore[attr-defined]


# -- its physics body and driver --
class Quadruped:
    """A torso and four legs, one body of simple shapes placed along its path each control
    period (its gait is not simulated): walls, robots and sensors meet it like any body."""

    centre_height = LEGS + BODY[2] / 2  # m from the floor to the torso's centre

    def __init__(self, client: PhysicsClient, centre: FloatArray) -> None:
        self.client = client
        half = [v / 2 for v in BODY]
        hips = [(sx * (half[0] - 0.08), sy * (half[1] - 0.03), -half[2] - LEGS / 2)
                for sx in (1, -1) for sy in (1, -1)]
        shape = client.call(
            "createCollisionShapeArray", [3] + [7] * 4,  # a box and four capsules
            halfExtents=[half] + [[0, 0, 0]] * 4, radii=[0] + [0.04] * 4,
            lengths=[0] + [LEGS - 0.08] * 4,
            collisionFramePositions=[[0.0, 0.0, 0.0]] + [list(h) for h in hips])
        self.body = int(client.call("createMultiBody", 0, shape,
                                    basePosition=[float(v) for v in centre]))

    def place(self, centre: FloatArray, yaw: float) -> None:
        self.client.call("resetBasePositionAndOrientation", self.body,
                         [float(v) for v in centre],
                         [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)])

    def position(self) -> FloatArray:
        pos, _ = self.client.call("getBasePositionAndOrientation", self.body)
        return np.array(pos)


@DRIVERS.register(KIND)
class LeggedDriver(PlacedDriver):
    """Trots its path at its speed, placed each control period; it waits rather than step
    into another robot."""

    body_class = Quadruped
    turns = True  # its long body faces the way it trots


# -- its look in a recording --
@LOOKS.register("quadruped")
def _quadruped(rr: object, rec: object, entity: str, color: Color, kind: KindDefaults) -> None:
    """Its torso as a box and its four legs as lines down to the floor."""
    top = -kind.height + LEGS + BODY[2] / 2  # the torso's centre, below the camera
    half = (BODY[0] / 2, BODY[1] / 2, BODY[2] / 2)
    rec.log(entity + "/torso", rr.Boxes3D(  # type: ignore[attr-defined]
        half_sizes=[half], centers=[(0.0, 0.0, top)], colors=[color], fill_mode="solid"),
        static=True)
    feet = [((sx * half[0], sy * half[1], top), (sx * half[0], sy * half[1], -kind.height))
            for sx in (0.9, -0.9) for sy in (1, -1)]
    rec.log(entity + "/legs", rr.LineStrips3D(  # type: ignore[attr-defined]
        feet, colors=[color], radii=0.03), static=True)


# -- a strategy --
@register_strategy("timed")
def timed(agents: Sequence[Agent], rooms: Sequence[RoomInfo],
          weights: Weights) -> NDArray[np.float64]:
    """Eq. 1 with travel time in place of distance: each agent's distance over its kind's
    cruise speed, normalised by the mean over the whole team (not per agent, as Eq. 1 does, so
    a faster robot is sent farther), plus the risk and messiness terms."""
    speed = np.array([KIND_DEFAULTS[a.kind].speed for a in agents])
    t = distances(agents, rooms) / speed[:, None]
    mean = float(t.mean()) if t.size else 0.0
    w = np.array([weights.of(a.kind) for a in agents], dtype=float).reshape(len(agents), 2)
    risk = np.array([r.risk for r in rooms])
    mess = np.array([r.messiness for r in rooms])
    norm = t / mean if mean > 0 else np.zeros_like(t)
    return np.asarray(norm + w[:, :1] * risk[None, :] + w[:, 1:] * mess[None, :])
