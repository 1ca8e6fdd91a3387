"""Mesh readers (OBJ, glTF/GLB, STL, through trimesh) and what a world needs of a mesh: its up
axis, the voxels its surface passes through, and its floors by the floor-normal analysis that
clutter placement uses (:mod:`astralis_des.world.freespace`: triangles facing up, n_z > UP).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from astralis_des.importers.pointcloud import library_error
from astralis_des.importers.source import Mesh, ReadRequest, reader
from astralis_des.importers.voxels import unique_rows, voxel_index
from astralis_des.world.freespace import FLOOR_TOLERANCE, UP
from astralis_des.world.geometry import FloatArray

IntArray = NDArray[np.int64]
MIN_FLOOR_AREA = 20.0  # m^2 of level triangles at one height for it to be a floor
CHUNK_POINTS = 2_000_000  # surface samples turned into voxels at a time


@reader("obj", "stl", "gltf", "glb", memory_per_byte=12.0)
def read_mesh(path: Path, request: ReadRequest) -> Mesh:
    """One mesh of every part of the file (a scene's parts placed by their transforms)."""
    import trimesh

    kind = path.suffix.lower().lstrip(".")
    try:
        loaded: Any = trimesh.load(path, force="mesh")
    except Exception as exc:  # trimesh raises many kinds for a bad file
        raise library_error(path, kind.upper(), exc) from None
    faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64).reshape(-1, 3)
    vertices = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=float)
    up = "y" if kind in ("gltf", "glb") else None  # glTF is Y-up by its specification
    return Mesh(vertices.reshape(-1, 3), faces, up,
                watertight=bool(len(faces)) and bool(loaded.is_watertight))


def triangles(vertices: FloatArray, faces: IntArray) -> FloatArray:
    return np.asarray(vertices)[np.asarray(faces)]


def face_normals(tri: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Unit normals (zero for degenerate faces) and areas."""
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(cross, axis=1)
    unit = cross / np.where(length > 0, length, 1.0)[:, None]
    return unit, length / 2


def choose_up(mesh: Mesh, up: str) -> str:
    """``y`` or ``z``: as asked, else as the format says, else the axis more of the surface
    faces (floors, roofs and ground face up or down; walls face sideways)."""
    if up != "auto":
        return up
    if mesh.up is not None:
        return mesh.up
    normal, area = face_normals(triangles(mesh.vertices, mesh.faces))
    facing = [float(area[np.abs(normal[:, k]) > UP].sum()) for k in (1, 2)]
    return "y" if facing[0] > facing[1] else "z"


def to_z_up(vertices: FloatArray, up: str) -> FloatArray:
    """Y-up to Z-up is a quarter turn about x: (x, y, z) -> (x, -z, y)."""
    v = np.asarray(vertices, dtype=float)
    if up == "z":
        return v.copy()
    return np.column_stack([v[:, 0], -v[:, 2], v[:, 1]])


def closed_faces(vertices: FloatArray, faces: IntArray) -> NDArray[np.bool_]:
    """``(F,)``: is each face part of a closed component (every edge shared by two faces),
    whose inside is solid? Vertices closer than a micrometre are one."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    _, same = np.unique(np.round(np.asarray(vertices) * 1e6).astype(np.int64), axis=0,
                        return_inverse=True)
    f = same.reshape(-1)[faces]
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    n = int(same.max()) + 1
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    key = edges[:, 0] * n + edges[:, 1]
    unique, counts = np.unique(key, return_counts=True)
    open_edges = unique[counts != 2] // n
    open_parts = np.zeros(int(label.max()) + 1, dtype=bool)
    open_parts[label[open_edges]] = True
    return np.asarray(~open_parts[label[f[:, 0]]])


def surface_voxels(tri: FloatArray, voxel: float) -> IntArray:
    """Unique ``(M, 3)`` voxels the triangles' surface passes through, found from points at
    most half a voxel apart on every triangle (no random draws): rows parallel to the longest
    edge, as many as the triangle's height needs, so a long sliver costs a row, not a square.
    """
    step = voxel / 2
    tri = np.asarray(tri, dtype=float)
    edges = np.linalg.norm(tri[:, [1, 2, 0]] - tri, axis=2)  # edge k runs from vertex k
    longest = np.argmax(edges, axis=1)
    rows = np.arange(len(tri))
    a = tri[rows, longest]
    b = tri[rows, (longest + 1) % 3]
    c = tri[rows, (longest + 2) % 3]
    length = edges[rows, longest]
    area2 = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    height = area2 / np.where(length > 0, length, 1.0)
    along = np.maximum(np.ceil(length / step), 1).astype(np.int64)
    across = np.maximum(np.ceil(height / step), 1).astype(np.int64)
    count = (along + 1) * (across + 1)
    found: list[IntArray] = []
    first = 0
    while first < len(tri):
        last = first + max(int(np.searchsorted(np.cumsum(count[first:]), CHUNK_POINTS)), 1)
        pick = slice(first, last)
        n1, m, k_count = along[pick], across[pick], count[pick]
        which = np.repeat(np.arange(last - first), k_count)
        k = np.arange(int(k_count.sum())) - np.repeat(np.cumsum(k_count) - k_count, k_count)
        s_ = (k % (n1 + 1)[which]) / n1[which]
        t = (k // (n1 + 1)[which]) / m[which]
        pa, pb, pc = a[pick][which], b[pick][which], c[pick][which]
        points = pa + t[:, None] * (pc - pa) + (s_ * (1 - t))[:, None] * (pb - pa)
        found.append(unique_rows(voxel_index(points, voxel)))
        first = last
    if not found:
        return np.zeros((0, 3), dtype=np.int64)
    return unique_rows(np.concatenate(found))


def floor_levels(tri: FloatArray) -> list[tuple[float, float]]:
    """``(height, area)`` of each floor, lowest first: the heights holding the most area of
    level triangles facing up (n_z > UP, every vertex within ``FLOOR_TOLERANCE``), taken
    greedily, heaviest first, while one holds at least ``MIN_FLOOR_AREA``."""
    normal, area = face_normals(tri)
    z = tri[:, :, 2].mean(axis=1)
    flat = (normal[:, 2] > UP) & (np.ptp(tri[:, :, 2], axis=1) <= 2 * FLOOR_TOLERANCE)
    z, a = z[flat], area[flat]
    levels = []
    while len(z):
        bins = np.round(z / 0.01).astype(np.int64)
        keys, inverse = np.unique(bins, return_inverse=True)
        weight = np.bincount(inverse, weights=a)
        # the area within FLOOR_TOLERANCE of each centimetre: a window sum over the bins
        span = round(FLOOR_TOLERANCE / 0.01)
        cum = np.concatenate([[0.0], np.cumsum(weight)])
        lo = np.searchsorted(keys, keys - span)
        hi = np.searchsorted(keys, keys + span, side="right")
        around = cum[hi] - cum[lo]
        best = int(np.argmax(around))
        if around[best] < MIN_FLOOR_AREA:
            break
        near = np.abs(z - keys[best] * 0.01) <= FLOOR_TOLERANCE
        levels.append((round(float(np.average(z[near], weights=a[near])), 3),
                       float(a[near].sum())))
        z, a = z[~near], a[~near]
    return sorted(levels)


def floor_cells(tri: FloatArray, level: float, shape: tuple[int, int],
                cell: float) -> NDArray[np.bool_]:
    """``(nx, ny)`` cells under upward triangles at ``level``: where one can stand."""
    normal, _ = face_normals(tri)
    on = (normal[:, 2] > UP) & np.all(np.abs(tri[:, :, 2] - level) <= FLOOR_TOLERANCE, axis=1)
    mask = np.zeros(shape, dtype=bool)
    if not on.any():
        return mask
    voxels = surface_voxels(tri[on], cell)
    inside = (voxels[:, 0] >= 0) & (voxels[:, 0] < shape[0]) & (voxels[:, 1] >= 0) & \
        (voxels[:, 1] < shape[1])
    mask[voxels[inside, 0], voxels[inside, 1]] = True
    return mask


def mesh_extent(vertices: FloatArray) -> FloatArray:
    lo, hi = np.asarray(vertices).min(axis=0), np.asarray(vertices).max(axis=0)
    return np.asarray(hi - lo)


def decimals_for(voxel: float) -> int:
    """Digits to write coordinates with: a thousandth of a voxel."""
    return max(math.ceil(-math.log10(voxel / 1000)), 1)
