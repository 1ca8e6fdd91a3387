"""Free points a robot may start at (``astralis world spots``), the nearest to a point first.

Outdoors, points of a grid over the site; indoors, each room's centre and points along each
corridor, on their floor. A point is listed only if a mission's start there passes the
validator's own check (:func:`astralis_des.world.placement.problem`) for every kind asked for:
clear of every solid by the body's radius, in a place the router knows.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from astralis_des.errors import InputError
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.world.geometry import FloatArray
from astralis_des.world.model import World
from astralis_des.world.placement import blocking, problem, shown

Where = Literal["outdoor", "indoor", "both"]
SPACING = 2.0  # m between outdoor spots, and between a corridor's
REACHES = (16.0, 64.0)  # m round the point searched outdoors in turn, then the whole site


@dataclass(frozen=True)
class Spot:
    point: tuple[float, float, float]
    place: str  # "outdoor", a room id or a corridor id
    distance: float  # m from the point asked about, in the plane

    def start(self) -> str:
        """The point as a mission's ``start:`` writes it."""
        return shown(self.point)


def reference(world: World) -> tuple[float, float]:
    """Where spots are nearest to unless told: the first building's entrance (where a study
    draws outdoor starts), else the middle of the site."""
    if world.entrances:
        x, y, _ = world.entrances[min(world.entrances)]
        return (float(x), float(y))
    return (world.site[0] / 2, world.site[1] / 2)


def free_spots(world: World, kinds: Sequence[str], *, near: tuple[float, float] | None = None,
               count: int = 10, where: Where = "both", spacing: float = SPACING) -> list[Spot]:
    """The ``count`` free spots nearest ``near`` (default: :func:`reference`) where a robot of
    each of ``kinds`` may start; ties by height, then x, then y."""
    centre = np.array(near if near is not None else reference(world), dtype=float)
    radius = max(KIND_DEFAULTS[k].radius for k in kinds)
    found: list[Spot] = []
    if where in ("indoor", "both"):
        found += _indoor(world, centre, radius, spacing)
    if where in ("outdoor", "both"):
        found += _outdoor(world, centre, radius, spacing, count)
    found.sort(key=lambda s: (s.distance, s.point[2], s.point[0], s.point[1]))
    spots: list[Spot] = []
    for spot in found:  # the validator's own check of a start
        if all(problem(world, spot.point, k) is None for k in kinds):
            spots.append(spot)
            if len(spots) == count:
                break
    return spots


def _indoor(world: World, centre: FloatArray, radius: float, spacing: float) -> list[Spot]:
    """Each room's centre, and points ``spacing`` apart along each corridor's middle."""
    points = [np.array([*r.box.center[:2], r.box.lo[2]]) for r in world.rooms.values()]
    for space in world.spaces.values():
        if space.kind == "corridor":
            points += _along(np.array(space.box.lo), np.array(space.box.hi), spacing)
    return _clear(world, np.array(points).reshape(-1, 3), centre, radius, indoor=True)


def _along(lo: FloatArray, hi: FloatArray, spacing: float) -> list[FloatArray]:
    """Points of the grid ``spacing`` apart along a box's long axis, on its middle line, at
    its floor (its middle if it is shorter than ``spacing``)."""
    axis = int(np.argmax((hi - lo)[:2]))
    mid = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
    steps = np.arange(np.floor(lo[axis] / spacing) + 1, np.ceil(hi[axis] / spacing)) * spacing
    out = []
    for v in steps if len(steps) else [mid[axis]]:
        p = mid.copy()
        p[axis] = v
        out.append(p)
    return out


def _outdoor(world: World, centre: FloatArray, radius: float, spacing: float,
             count: int) -> list[Spot]:
    """Grid points ``spacing`` apart outdoors, a body's radius inside the site's edges,
    searched in growing squares round ``centre`` until ``count`` of them lie within the
    square's reach (so that no nearer one is left out)."""
    size = np.array(world.site, dtype=float)
    whole = float(np.hypot(*size))
    spots: list[Spot] = []
    for reach in (*REACHES, whole):
        lo = np.ceil(np.maximum(centre - reach, radius) / spacing)
        hi = np.floor(np.minimum(centre + reach, size - radius) / spacing)
        gx, gy = np.meshgrid(np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1),
                             indexing="ij")
        xy = np.column_stack([gx.ravel(), gy.ravel()]) * spacing
        points = np.column_stack([xy, np.zeros(len(xy))])
        spots = _clear(world, points, centre, radius, indoor=False, count=count)
        if reach == whole or (len(spots) >= count and spots[-1].distance <= reach):
            break
    return spots


def _clear(world: World, points: FloatArray, centre: FloatArray, radius: float, *,
           indoor: bool, count: int | None = None) -> list[Spot]:
    """Of ``points``, nearest ``centre`` first, those clear of every solid by ``radius`` in a
    place the router knows (a room or corridor if ``indoor``, else outdoors); at most
    ``count``."""
    if not len(points):
        return []
    offset = points[:, :2] - centre
    distance = np.round(np.sqrt(np.einsum("ij,ij->i", offset, offset)), 6)
    order = np.lexsort((points[:, 1], points[:, 0], points[:, 2], distance))
    solid, _ = blocking(world, points[order], radius)
    spots: list[Spot] = []
    for i in order[solid < 0]:
        try:
            place = world.router.place_of(points[i])
        except InputError:
            continue
        if (place == "outdoor") is indoor:
            continue
        x, y, z = (round(float(v), 2) + 0.0 for v in points[i])
        spots.append(Spot((x, y, z), place, float(distance[i])))
        if count is not None and len(spots) == count:
            break
    return spots


def spot_lines(world: World, spots: list[Spot], kinds: Sequence[str],
               near: tuple[float, float] | None) -> list[str]:
    """A headline, then a line a spot (plain text: read, grepped and pasted into a mission)."""
    centre = near if near is not None else reference(world)
    lines = [f"world {world.name}: starts free for {', '.join(kinds)}, nearest "
             f"{shown(centre)} first"]
    if not spots:
        return lines
    width = max(len(s.start()) for s in spots)
    place = max([len(s.place) for s in spots] + [5])
    lines.append(f"{'start':<{width}}  {'place':<{place}}  m away")
    lines += [f"{s.start():<{width}}  {s.place:<{place}}  {s.distance:6.1f}" for s in spots]
    return lines
