"""Where a robot may stand: clear of every solid by its body's radius, on the site, in a place
the router knows; and, where it may not, the nearest point where it may.

A start inside a wall validated, then walked through walls (kinematic) or stuck (physics).
"""

from __future__ import annotations

import numpy as np

from astralis_des.errors import InputError
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.world.geometry import FloatArray
from astralis_des.world.model import World
from astralis_des.world.parts import BLOCK, Solid

LIFT = 0.05  # m: a body stands this far above its point: the slab it stands on is not in it
REACH = 1.0  # m above the point: what stands lower than this (a wall, a tree, a car) is in
# its way; a door's lintel (2.1 m) is not
STEP = 0.1  # m: the grid the nearest free point is sought on
RINGS = ((2.0, STEP), (8.0, STEP), (32.0, 0.5))  # m searched round a point in turn, each on
# a grid of its step (m)


def shown(point: tuple[float, ...] | FloatArray) -> str:
    """``[x, y, z]`` as a mission writes it."""
    return "[" + ", ".join(f"{round(float(v), 2) + 0.0:g}" for v in point) + "]"


def blocking(world: World, points: FloatArray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """``(N,)`` index into ``world.solids`` of a solid within ``radius`` (in the plane) of a
    body standing at each point (-1: none), and ``(N,)`` whether the point is inside it."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    which = np.full(len(pts), -1)
    inside = np.zeros(len(pts), dtype=bool)
    boxes = world.solid_array
    if not len(pts):
        return which, inside
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    near = np.flatnonzero(
        (boxes[:, 0, 0] < hi[0] + radius) & (boxes[:, 1, 0] > lo[0] - radius)
        & (boxes[:, 0, 1] < hi[1] + radius) & (boxes[:, 1, 1] > lo[1] - radius)
        & (boxes[:, 0, 2] < hi[2] + REACH) & (boxes[:, 1, 2] > lo[2] + LIFT))
    if not len(near):
        return which, inside
    chunk = max(1, 2_000_000 // max(len(near), 1))
    for start in range(0, len(pts), chunk):
        p = pts[start:start + chunk, None, :]
        b = boxes[near][None]
        gap = np.maximum(np.maximum(b[..., 0, :2] - p[..., :2], p[..., :2] - b[..., 1, :2]), 0.0)
        level = (b[..., 0, 2] < p[..., 2] + REACH) & (b[..., 1, 2] > p[..., 2] + LIFT)
        hit = level & (np.einsum("nkj,nkj->nk", gap, gap) < radius * radius)
        found = hit.any(axis=1)
        first = np.argmax(hit, axis=1)
        which[start:start + len(p)] = np.where(found, near[first], -1)
        inside[start:start + len(p)] = found & ~np.take_along_axis(
            gap.any(axis=2), first[:, None], axis=1)[:, 0]
    return which, inside


def what(solid: Solid) -> str:
    """A solid as an error names it: "a wall of building A", "a tree"."""
    building = solid.label.split(".")[0].split(" ")[0]
    if solid.kind == "wall":
        return f"a wall of building {building}"
    if solid.kind == "slab":
        return "the ground" if solid.label == "ground" else f"a floor of building {building}"
    if solid.kind == BLOCK:
        return "a block of the imported world"
    return f"a {solid.kind.replace('_', ' ')}"


def problem(world: World, point: tuple[float, ...] | FloatArray, kind: str) -> str | None:
    """Why a robot of ``kind`` cannot stand at ``point``, naming the nearest point where it
    can; ``None`` if it can."""
    radius = KIND_DEFAULTS[kind].radius
    p = np.asarray(point, dtype=float)
    solid, inside = blocking(world, p, radius)
    if solid[0] >= 0:
        thing = what(world.solids[solid[0]])
        why = (f"{shown(p)} is inside {thing}" if inside[0] else
               f"{shown(p)} is too close to {thing} for a {kind} (its body reaches "
               f"{radius:g} m from its centre)")
    else:
        try:
            world.router.place_of(p)
            return None
        except InputError as exc:
            why = exc.message
    near = nearest_free(world, p, radius)
    if near is None:
        return f"{why}; there is no free point within {RINGS[-1][0]:g} m"
    return f"{why}; the nearest free point is {shown(near)}"


def nearest_free(world: World, point: FloatArray, radius: float) -> FloatArray | None:
    """The point nearest ``point`` (on the site, at its height, on a grid of ``STEP``) where
    a body of ``radius`` stands clear of every solid in a place the router knows."""
    size = np.array(world.site, dtype=float)
    centre = np.clip(point[:2], 0.0, size)
    for reach, step in RINGS:
        n = int(reach / step)
        base = np.round(centre / step)
        gx, gy = np.meshgrid(np.arange(-n, n + 1), np.arange(-n, n + 1), indexing="ij")
        xy = (base + np.column_stack([gx.ravel(), gy.ravel()])) * step
        xy = xy[np.all((xy >= 0.0) & (xy <= size), axis=1)]
        candidates = np.column_stack([xy, np.full(len(xy), point[2])])
        d = np.round(np.linalg.norm(candidates[:, :2] - point[:2], axis=1), 6)
        candidates = candidates[np.lexsort((candidates[:, 1], candidates[:, 0], d))]
        solid, _ = blocking(world, candidates, radius)
        for c in candidates[solid < 0]:  # the router knows the place (not a closed space)
            try:
                world.router.place_of(c)
            except InputError:
                continue
            return np.asarray(c)
    return None
