"""The one way the package caches: on the object an answer depends on, for as long as it lives.

A world is built once per file content and process (``world.build.load_world``), so what is
kept on it serves every mission on that world in the process: a study's variants, a tune's
trials, a notebook's runs. Each cache is a dict on its owner, named here, emptied when it
reaches its limit; none is global, and none changes what a run computes (each holds what its
key alone determines: event logs are the same with every cache empty).

What is kept, on what (``kept(owner, NAME)``):

- on a **world**: ``voxel_map`` (the planner's occupancy map, by resolution and margin),
  ``block_field`` (an imported world's blocks, for going round them), ``free_space`` (each
  room's free floor, by cell size), ``furnished`` (a room's furniture, by its draw),
  ``coverage`` and ``first_pass`` (how much of a room a sweep sees), ``floor_cells`` (a
  room's coverage cells, and whether they lie in it alone), ``sky`` (the GNSS's open
  sky), ``ducked`` (legs that duck under a lintel), ``walk_boxes`` (the boxes along a
  walker's loop a landing UAV keeps off, by loop and size), and its router's Dijkstra rows
  (``world.routing``, its own cache, at most 256 MB);
- on a world's **router**: ``routes`` (waypoints, by ends and kind, read-only) and
  ``places`` (the place of a point);
- on a **voxel map**: ``occupied_points`` (its occupied cells' centres);
- on a room's **clutter** (kept on the world, above): ``still_boxes`` (the corners of what
  stays put in it, read-only);
- on a room's **free space**: ``empty_reach`` (where a robot reaches in the empty room, by
  passage; the bounds of its door cells) and ``wall_backs`` (where a footprint's back lies
  along a wall, and the windows there, by wall and footprint).

Elsewhere, once per process and by value (``functools``): the packaged clutter catalogue, the
ROS 2 message types, a camera's swath by view and height, a catalogue without its furniture,
a motion's course by path and speed parameters (with the sighting samples along it,
``kernel.course``), the ring of cells round a footprint by its size (``world.placing``), a
world's solids as Rerun chunks once recorded twice and a layout's blueprint encoded
(``sinks.prepared``, ``sinks.blueprint``: not on the world, which a study pickles for its
workers), and the built worlds themselves (by file content and the robot kinds
registered).

The registries (kinds, actions, strategies, planners, drivers, looks, event kinds) fill as
their modules and the plug-ins are imported, and last for the process: a plug-in a mission
names is imported once, and its kinds and actions stay for the missions after it.
"""

from __future__ import annotations

from typing import Any

NAMES = frozenset({"voxel_map", "block_field", "free_space", "furnished", "coverage",
                   "floor_cells", "first_pass", "sky", "ducked", "walk_boxes",
                   "occupied_points", "empty_reach", "wall_backs", "routes", "places",
                   "still_boxes"})
_ATTRIBUTES = {name: f"_memo_{name}" for name in NAMES}  # where each is kept on its owner


def kept(owner: object, name: str, limit: int | None = None) -> dict[Any, Any]:
    """The cache ``name`` kept on ``owner`` (made empty the first time), emptied when it holds
    ``limit`` entries. ``name`` is one of :data:`NAMES`, each documented above."""
    attribute = _ATTRIBUTES.get(name)
    if attribute is None:
        raise KeyError(f"cache {name!r} is not one of astralis_des.memo.NAMES: document it")
    cache: dict[Any, Any] = owner.__dict__.setdefault(attribute, {})
    if limit is not None and len(cache) >= limit:
        cache.clear()
    return cache
