"""How a recording draws things: where in the world each box belongs (building and storey),
one colour per robot, robots as shapes turned to their heading, avatars in their Table II
colour. How a kind is drawn is its record's ``look``, an entry of ``LOOKS``."""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Sequence
from functools import lru_cache
from typing import Any

import numpy as np

from astralis_des.kernel.robot import Robot
from astralis_des.kinds import KIND_DEFAULTS, KindDefaults
from astralis_des.registry import Registry
from astralis_des.sinks import paths
from astralis_des.sinks.columns import (
    SOLID,
    Columns,
    colors,
    descriptor,
    floats,
    rows,
    send,
    static_columns,
    strips,
    times,
    vectors,
)
from astralis_des.world.clutter import Placed
from astralis_des.world.geometry import Box
from astralis_des.world.model import World

# One colour per robot, in team order (Okabe-Ito's colour-blind-safe set, then more).
ROBOT_PALETTE: tuple[tuple[int, int, int, int], ...] = (
    (0, 114, 178, 255), (230, 159, 0, 255), (0, 158, 115, 255), (204, 121, 167, 255),
    (86, 180, 233, 255), (213, 94, 0, 255), (240, 228, 66, 255), (120, 80, 200, 255),
    (140, 140, 140, 255), (60, 60, 60, 255))
TABLE_II_COLORS = {"yellow": (240, 200, 40, 255), "red": (215, 40, 40, 255),
                   "purple": (140, 60, 170, 255), "blue": (40, 90, 215, 255)}
SOLID_COLORS = {"wall": (170, 170, 180, 255), "slab": (120, 120, 130, 60)}
OBSTACLE_COLOR = (60, 140, 60, 255)  # a tree, a parked vehicle, a lamp post
ROAD_COLOR = (60, 60, 65, 255)
FURNITURE_COLORS = {"chair": (139, 90, 43, 255), "cabinet": (110, 110, 90, 255),
                    "table": (181, 136, 99, 255), "potted_plant": (34, 139, 34, 255),
                    "computer_desk": (90, 90, 130, 255), "avatar": (250, 200, 60, 255)}
FURNITURE_COLOR = (150, 150, 150, 255)  # a kind FURNITURE_COLORS does not name


def solid_color(kind: str) -> tuple[int, int, int, int]:
    """A solid's colour by its kind: a wall's, a slab's, else an outdoor obstacle's."""
    return SOLID_COLORS.get(kind, OBSTACLE_COLOR)


def placed_color(placed: Placed) -> tuple[int, int, int, int]:
    """A piece of furniture's colour by its kind; an avatar's, its Table II colour."""
    return TABLE_II_COLORS.get(str(dict(placed.attributes).get("color")),
                               FURNITURE_COLORS.get(placed.kind, FURNITURE_COLOR))
UAV_ARMS = 6
UAV_ARM = 0.3  # m, centre to rotor tip (the hexacopter's collision radius)
HUMAN_HALF = (0.25, 0.2, 0.85)  # m: a walking person's box, half sizes


def robot_colors(robots: Sequence[str]) -> dict[str, tuple[int, int, int, int]]:
    """Each robot's colour, used in every panel (pose, trail, plan, body, distance series)."""
    return {rid: ROBOT_PALETTE[i % len(ROBOT_PALETTE)] for i, rid in enumerate(robots)}


def place_of(world: World, box: Box) -> str:
    """``A/2`` for a box of storey 2 of building A (its floor slab included), ``A/roof`` for
    the slab over the top storey, ``site`` for one outdoors."""
    centre = [(lo + hi) / 2 for lo, hi in zip(box.lo, box.hi, strict=True)]
    for bid, b in world.buildings.items():
        lo, hi = b.footprint.lo, b.footprint.hi
        if lo[0] - 0.5 <= centre[0] <= hi[0] + 0.5 and lo[1] - 0.5 <= centre[1] <= hi[1] + 0.5:
            storey = math.floor((centre[2] + 0.3) / b.floor_height) + 1
            return f"{bid}/roof" if storey > b.floors else f"{bid}/{max(storey, 1)}"
    return "site" if world.interior is None else interior_places(world, np.array([centre]))[0]


def interior_places(world: World, centres: np.ndarray) -> list[str]:
    """For each of ``centres`` (``(N, 3)``) in the interior's bounds, ``G/2`` (its storey: the
    highest floor at most 0.3 m over it, so a storey's ceiling goes with the storey above) or
    ``G/roof`` (the top 0.3 m); ``site`` elsewhere."""
    inner = world.interior
    out = np.full(len(centres), "site", dtype=object)
    if inner is None or not len(centres):
        return list(out)
    lo, hi = np.array(inner.footprint.lo) - 0.5, np.array(inner.footprint.hi) + 0.5
    inside = np.all((centres[:, :2] >= lo[:2]) & (centres[:, :2] <= hi[:2]), axis=1)
    storey = np.maximum(np.searchsorted(np.array(inner.storeys), centres[:, 2] + 0.3,
                                        side="right"), 1)
    out[inside] = [f"{inner.group}/{n}" for n in storey[inside]]
    out[inside & (centres[:, 2] > inner.footprint.hi[2] - 0.3)] = f"{inner.group}/roof"
    return list(out)


def by_place(world: World, boxes: Sequence[Box]) -> dict[str, list[int]]:
    """Indices of ``boxes`` grouped by :func:`place_of`, in a stable order."""
    groups: dict[str, list[int]] = defaultdict(list)
    for i, box in enumerate(boxes):
        groups[place_of(world, box)].append(i)
    return dict(sorted(groups.items()))


def headings(points: np.ndarray, start: float) -> np.ndarray:
    """The heading at each trail point: the direction of the leg it ends (the heading before
    for a point that did not move in the plane)."""
    if len(points) < 2:
        return np.full(len(points), float(start))
    steps = points[1:, :2] - points[:-1, :2]
    moved = np.hypot(steps[:, 0], steps[:, 1]) > 1e-6
    last = np.maximum.accumulate(np.where(moved, np.arange(len(steps)), -1))  # last move
    legs = np.arctan2(steps[:, 1], steps[:, 0])
    return np.concatenate([[float(start)],
                           np.where(last >= 0, legs[np.maximum(last, 0)], float(start))])


def log_body(rr: Any, rec: Any, robot: Robot, color: tuple[int, int, int, int]) -> None:
    """The robot's shape at ``robots/<id>/body``: a hexacopter's arms and rotors, the
    Husky's box, a person's box; moved along its trail and turned to its heading."""
    entity = paths.robot_body(robot.id)
    pts = np.array(robot.trail_p, dtype=float)
    if not len(pts):
        return
    yaw = headings(pts, robot.heading)
    quats = np.column_stack([np.zeros(len(yaw)), np.zeros(len(yaw)), np.sin(yaw / 2),
                             np.cos(yaw / 2)])
    send(rec, entity, times(np.array(robot.trail_t, dtype=float)), {
        descriptor("Transform3D", "translation"): rows(vectors(pts, 3)),
        descriptor("Transform3D", "quaternion"): rows(vectors(quats, 4))})
    kind = KIND_DEFAULTS[robot.kind]
    LOOKS.get(kind.look)(rr, rec, entity, color, kind)


Color = tuple[int, int, int, int]
# look -> draw(rr, recording, entity, colour, the kind's record): a robot's body, logged once
LOOKS: Registry[str, Callable[[Any, Any, str, Color, KindDefaults], None]] = Registry("look")


def send_parts(rec: Any, entity: str, parts: dict[str, Columns]) -> None:
    """Each part of a robot's body, static, under ``entity``."""
    for part, columns in parts.items():
        send(rec, f"{entity}/{part}", None, columns)


# The built-in looks' columns are the same from run to run: made once per kind and colour.
@LOOKS.register("rotorcraft")
def _rotorcraft(rr: Any, rec: Any, entity: str, color: Color, kind: KindDefaults) -> None:
    """Its arms out to the rotors and a nose along its heading."""
    send_parts(rec, entity, _rotorcraft_parts(color))


@lru_cache(maxsize=64)
def _rotorcraft_parts(color: Color) -> dict[str, Columns]:
    angles = np.arange(UAV_ARMS) * (2 * math.pi / UAV_ARMS) + math.pi / UAV_ARMS
    tips = np.column_stack([UAV_ARM * np.cos(angles), UAV_ARM * np.sin(angles),
                            np.zeros(UAV_ARMS)])
    arms = [np.array([[0.0, 0.0, 0.0], tip]) for tip in tips]
    nose = [np.array([[0.0, 0.0, 0.0], [UAV_ARM * 1.3, 0.0, 0.0]])]  # its heading
    return {"arms": static_columns("LineStrips3D", strips=strips(arms + nose),
                                   colors=colors([color]), radii=floats([0.025])),
            "rotors": static_columns("Points3D", positions=vectors(tips, 3),
                                     colors=colors([color]), radii=floats([0.08]))}


@LOOKS.register("rover")
def _rover(rr: Any, rec: Any, entity: str, color: Color, kind: KindDefaults) -> None:
    """A solid hull of its footprint (or its disc's square) and an arrow out of its front."""
    send_parts(rec, entity, _rover_parts(color, kind.footprint or (kind.length, kind.length)))


@lru_cache(maxsize=64)
def _rover_parts(color: Color, footprint: tuple[float, float]) -> dict[str, Columns]:
    length, width = footprint
    return {"hull": static_columns("Boxes3D", half_sizes=vectors([(length / 2, width / 2, 0.2)],
                                                                 3),
                                   centers=vectors([(0.0, 0.0, -0.2)], 3),
                                   colors=colors([color]), fill_mode=SOLID),
            "front": static_columns("Arrows3D", origins=vectors([(0.0, 0.0, 0.05)], 3),
                                    vectors=vectors([(length / 2 + 0.3, 0.0, 0.0)], 3),
                                    colors=colors([(255, 255, 255, 255)]))}


@LOOKS.register("person")
def _person(rr: Any, rec: Any, entity: str, color: Color, kind: KindDefaults) -> None:
    """A standing person's box, its top a little over its eyes."""
    send_parts(rec, entity, _person_parts(color, kind.height))


@lru_cache(maxsize=64)
def _person_parts(color: Color, height: float) -> dict[str, Columns]:
    return {"person": static_columns("Boxes3D", half_sizes=vectors([HUMAN_HALF], 3),
                                     centers=vectors([(0.0, 0.0, HUMAN_HALF[2] - height)], 3),
                                     colors=colors([color]), fill_mode=SOLID)}


def by_height(z: np.ndarray, top: float = 12.0) -> np.ndarray:
    """RGB of points by their height: blue on the ground to a pale yellow ``top`` m up (the
    planner's occupancy map, the 3-D lidar's returns)."""
    h = np.clip(np.asarray(z, dtype=float) / top, 0.0, 1.0)
    return np.column_stack([60 + 150 * h, 90 + 60 * h, 200 - 120 * h]).astype(np.uint8)
