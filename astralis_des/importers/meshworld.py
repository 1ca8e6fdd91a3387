"""A mesh becomes a world: turned Z-up, scaled to metres, its lowest point on the ground; its
surface voxelised into blocks (filled inside when the mesh is closed) for sight and planning;
its floors found from triangles facing up, as clutter placement finds them; search areas on
the floors with headroom; and the mesh itself kept for the physics (a static concave mesh, or
its convex parts) and the replay.
"""

from __future__ import annotations

import logging
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage

from astralis_des.errors import InputError
from astralis_des.importers.areas import Area, Level, place_areas
from astralis_des.importers.indoor.surface import surface_points
from astralis_des.importers.indoor_world import (
    indoor_heading,
    indoor_section,
    outside_interior,
)
from astralis_des.importers.mesh import (
    choose_up,
    closed_faces,
    floor_cells,
    floor_levels,
    surface_voxels,
    to_z_up,
    triangles,
)
from astralis_des.importers.options import Built, ImportOptions
from astralis_des.importers.source import Mesh, finite_rows, unit_scale
from astralis_des.importers.survey import turn_about
from astralis_des.importers.voxels import boxes_from_indices, grid_shape, unique_rows
from astralis_des.world.geometry import FloatArray

log = logging.getLogger(__name__)

STAND = 0.3  # m above a floor from which headroom is counted
HEADROOM = 2.0  # m of clear height an area's floor needs
AREA_HEIGHT = 10.0  # m: the most an area reaches above its floor
MIN_AREA_HEIGHT = 2.5
AREA_LEVELS = 8  # the floors with the most area that search areas may be placed on
MESH_VOXEL = 0.2  # m, unless --voxel says
INDOOR_SPACING = 0.04  # m between the points an indoor mesh is sampled with (--indoor)
VHACD_RESOLUTION = 50_000  # voxels of V-HACD's decomposition (its default, 100,000, is slower)


def mesh_world(mesh: Mesh, path: Path, opts: ImportOptions) -> Built:
    voxel = opts.voxel or MESH_VOXEL
    good = finite_rows(mesh.vertices)
    dropped = int(len(good) - good.sum())
    faces = mesh.faces[good[mesh.faces].all(axis=1)] if dropped else mesh.faces
    if dropped:
        log.warning("%s: dropped %d vertices with NaN or infinite coordinates", path, dropped)
    if len(faces) == 0:
        raise InputError("the mesh has no faces" + (f" ({dropped:,} vertices with NaN or "
                         "infinite coordinates dropped)" if dropped else ""), file=path)
    up = choose_up(mesh, opts.up)
    scale = unit_scale(opts.units, None) * opts.scale
    upright = to_z_up(np.where(good[:, None], mesh.vertices, 0.0), up) * scale
    used = np.unique(faces)
    heading, pivot = 0.0, upright[used].mean(axis=0)
    points = np.zeros((0, 3))
    if opts.indoor:  # its surfaces as a cloud, turned so that the walls run along x and y
        points = surface_points(upright, faces, INDOOR_SPACING, seed=opts.seed)
        heading = indoor_heading(points, path)
        if heading:
            upright, points = (turn_about(a, -heading, pivot) for a in (upright, points))
    origin = upright[used].min(axis=0) - np.array([opts.margin, opts.margin, 0.0])
    vertices = upright - origin
    notes: list[str] = []
    interior = None
    if opts.indoor:  # storeys, rooms and doors, the lowest floor brought to z = 0
        interior, floor = indoor_section(points - origin, opts.group, path, notes,
                                         opts.door_max, heading)
        origin[2] += floor
        vertices[:, 2] -= floor
    tri = triangles(vertices, faces)
    extent = vertices[used].max(axis=0) + np.array([opts.margin, opts.margin, 0.0])
    shape = grid_shape(extent + voxel, voxel, what="the mesh")
    cells = surface_voxels(tri, voxel)
    closed = np.ones(len(faces), dtype=bool) if mesh.watertight else \
        closed_faces(vertices, faces)
    if closed.any():  # the insides of closed parts are solid too
        cells = unique_rows(np.vstack([cells, _inside(surface_voxels(tri[closed], voxel),
                                                      shape)]))
    cells = cells[cells[:, 2] >= 0]  # a surface at z = 0 lies on the ground plane
    boxes = boxes_from_indices(cells)
    found = floor_levels(tri)
    levels = sorted({0.0, *(z for z, _ in found)})
    widest = sorted(z for z, _ in sorted(found, key=lambda f: -f[1])[:AREA_LEVELS])
    if interior is not None:  # its walls and floors are made from it; the rest stays
        boxes = outside_interior(boxes, voxel, interior)
    areas = [] if opts.indoor else _areas(tri, cells, sorted({0.0, *widest}), shape, voxel,
                                          opts)
    collision = opts.collision if opts.collision != "auto" else \
        "boxes" if opts.indoor else "concave"
    parts = _convex_parts(vertices, faces) if collision == "convex" else None
    corner = turn_about(origin[None, :], heading, pivot)[0] if heading else origin
    back = _to_source(corner / scale, up)  # the origin in the file's frame
    source = {"kind": "mesh", "faces": len(mesh.faces), "dropped": dropped,
              "units": f"{opts.units} (given)" if opts.units != "auto" else
              "m (a mesh has no units: metres assumed)", "scale": round(scale, 9), "up": up,
              "offset": back}
    site = (shape[0] * voxel, shape[1] * voxel)
    return Built("mesh", site, voxel, boxes, areas, source, collision,
                 floors=levels, vertices=vertices, faces=faces, parts=parts,
                 stats={"watertight": mesh.watertight, "surface_voxels": len(cells),
                        "extent": tuple(float(v) for v in vertices[used].max(axis=0) -
                                        vertices[used].min(axis=0))},
                 notes=notes, interior=interior)


def _to_source(origin: FloatArray, up: str) -> tuple[float, float, float]:
    """The world origin in the file's axes (undoing the quarter turn of a Y-up file)."""
    x, y, z = (float(v) for v in origin)
    return (x, z, -y) if up == "y" else (x, y, z)


def _inside(cells: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """Closed surfaces' voxels and every voxel they enclose; the grid reaches one layer below
    the ground, where the faces lying on it are, so that they close what stands on them."""
    grid = np.zeros((shape[0], shape[1], shape[2] + 1), dtype=bool)
    keep = np.all((cells >= -1) & (cells < np.array(shape)), axis=1)
    grid[cells[keep, 0], cells[keep, 1], cells[keep, 2] + 1] = True
    filled = np.argwhere(ndimage.binary_fill_holes(grid))
    return filled - np.array([0, 0, 1])


def _areas(tri: FloatArray, cells: np.ndarray, levels: list[float], shape: tuple[int, ...],
           voxel: float, opts: ImportOptions) -> list[Area]:
    """Areas on each floor where nothing stands in the ``HEADROOM`` above it."""
    if opts.areas == 0:
        return []
    v = voxel
    plan = (shape[0], shape[1])
    found = []
    for z in levels:
        # A cell is floor when all its neighbours are too: a sampled edge spills into the
        # cell beside it, and an area must not overhang its floor.
        floor = np.ones(plan, dtype=bool) if z == 0.0 else ndimage.binary_erosion(
            floor_cells(tri, z, plan, v), np.ones((3, 3), dtype=bool))
        k0 = max(int(np.floor((z + STAND) / v)), int(np.floor(z / v - 1e-6)) + 1)
        k1 = int(np.ceil((z + HEADROOM) / v))
        above = cells[(cells[:, 2] >= k0) & (cells[:, 2] < k1)]
        blocked = np.zeros(plan, dtype=bool)
        blocked[np.minimum(above[:, 0], plan[0] - 1), np.minimum(above[:, 1], plan[1] - 1)] = True
        free = floor & ~ndimage.binary_dilation(blocked, np.ones((3, 3), dtype=bool))
        found.append(Level(z, free))
    # The modelled floors first, the most open one first; the ground around the model last.
    found.sort(key=lambda lv: (lv.z == 0.0, -int(lv.free.sum())))

    def headroom(z: float, si: slice, sj: slice) -> float:
        k0 = int(np.floor((z + STAND) / v)) + 1
        inside = (cells[:, 0] >= si.start) & (cells[:, 0] < si.stop) & \
            (cells[:, 1] >= sj.start) & (cells[:, 1] < sj.stop) & (cells[:, 2] >= k0)
        top = float(cells[inside, 2].min()) * v - z if inside.any() else AREA_HEIGHT
        return round(min(max(top, MIN_AREA_HEIGHT), AREA_HEIGHT), 3)

    return place_areas(found, v, opts.areas, opts.area_size, headroom)


def _convex_parts(vertices: FloatArray, faces: np.ndarray
                  ) -> list[tuple[FloatArray, np.ndarray]]:
    """Convex parts by PyBullet's V-HACD (quiet: it prints its progress)."""
    import trimesh

    from astralis_des.physics import pb  # PyBullet, loaded quietly
    from astralis_des.physics.quiet import quiet_c_output

    with tempfile.TemporaryDirectory(prefix="astralis-vhacd-") as folder:
        whole, parts = Path(folder) / "whole.obj", Path(folder) / "parts.obj"
        whole.write_text(trimesh.exchange.obj.export_obj(
            trimesh.Trimesh(vertices, faces, process=False), include_normals=False,
            include_texture=False), encoding="utf-8")
        with quiet_c_output():
            client = pb.connect(pb.DIRECT)
            try:
                pb.vhacd(str(whole), str(parts), str(Path(folder) / "vhacd.log"),
                         resolution=VHACD_RESOLUTION, physicsClientId=client)
            finally:
                pb.disconnect(physicsClientId=client)
        loaded: Any = trimesh.load(parts, force="mesh", process=False)
    # Each hull shares no vertex with another: the parts are the connected components.
    return [(np.asarray(m.vertices, dtype=float), np.asarray(m.faces, dtype=np.int64))
            for m in loaded.split(only_watertight=False)]
