"""An imported world in a recording: its blocks coloured by height, its mesh, its cloud."""

from __future__ import annotations

from typing import Any

import numpy as np

from astralis_des.sinks import paths
from astralis_des.sinks.looks import interior_places
from astralis_des.world.model import World

LOW, HIGH = np.array([70, 110, 160]), np.array([235, 225, 150])  # block colours by height
MESH_COLOR = (185, 180, 170, 255)


def log_imported(rr: Any, rec: Any, world: World) -> None:
    """Static, once: blocks (unless a mesh shows the same), the mesh, the cloud."""
    imported = world.imported
    blocks = world.block_array
    if len(blocks) and (imported is None or imported.vertices is None):
        top = blocks[:, 1, 2]
        t = np.clip(top / max(float(top.max()), 1e-6), 0.0, 1.0)[:, None]
        colors = (LOW + t * (HIGH - LOW)).astype(np.uint8)
        rec.log(paths.WORLD_BLOCKS, rr.Boxes3D(centers=blocks.mean(axis=1),
                                               half_sizes=(blocks[:, 1] - blocks[:, 0]) / 2,
                                               colors=colors, fill_mode="solid"), static=True)
    if imported is None:
        return
    if imported.vertices is not None and imported.faces is not None:
        centres = imported.vertices[imported.faces].mean(axis=1)
        for path, rows in _by_storey(world, centres, paths.WORLD_MESH, "mesh"):
            rec.log(path, rr.Mesh3D(vertex_positions=imported.vertices,
                                    triangle_indices=imported.faces[rows],
                                    albedo_factor=MESH_COLOR), static=True)
    if imported.cloud is not None and len(imported.cloud):
        colors = imported.cloud_colors
        for path, rows in _by_storey(world, imported.cloud, paths.WORLD_CLOUD, "cloud"):
            rec.log(path, rr.Points3D(imported.cloud[rows], colors=None if colors is None
                                      else colors[rows], radii=0.08), static=True)


def _by_storey(world: World, centres: np.ndarray, whole: str, what: str
               ) -> list[tuple[str, np.ndarray]]:
    """The rows of ``centres`` by the interior's storey they are on (``world/G/2/mesh``), so
    that the storeys over the robots and the roof can be hidden; all at ``whole`` in a world
    with no interior."""
    if world.interior is None:
        return [(whole, np.arange(len(centres)))]
    places = np.array(interior_places(world, centres), dtype=object)
    return [(paths.world_part(str(place), what), np.flatnonzero(places == place))
            for place in sorted(set(places.tolist()))]
