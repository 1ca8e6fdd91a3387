"""What a world file adds to the built world: search areas (rooms in the open) and an imported
world's geometry read from the files beside it (blocks, mesh, convex parts, cloud)."""

from __future__ import annotations

import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from astralis_des.errors import InputError
from astralis_des.world.geometry import Box, FloatArray
from astralis_des.world.parts import BLOCK, Door, Room, Segment, Solid
from astralis_des.world.spec import AreaSpec, GeometrySpec, SourceSpec
from astralis_des.yamlio import LocatedYaml

GROUND_DEPTH = 0.2  # m of ground slab under an imported site: the floor of its open areas
DOOR_WIDTH = 2.0  # m, an area's way in (routes cross its side square to it)


@dataclass(frozen=True, eq=False)
class Imported:
    """An imported world's own data; ``mesh`` and ``cloud`` are for the replay and the floors,
    ``mesh_file`` and ``parts_file`` for the physics."""

    voxel: float
    collision: str
    source: dict[str, Any] = field(default_factory=dict)
    floors: tuple[float, ...] = ()
    mesh_file: Path | None = None
    parts_file: Path | None = None
    vertices: FloatArray | None = None  # (V, 3)
    faces: NDArray[np.int64] | None = None  # (F, 3)
    cloud: FloatArray | None = None  # (N, 3)
    cloud_colors: NDArray[np.uint8] | None = None  # (N, 3)

    def triangles_near(self, lo: FloatArray, hi: FloatArray) -> tuple[FloatArray,
                                                                       NDArray[np.int64]]:
        """The mesh's triangles whose bounds meet ``[lo, hi]`` (3-D), as vertices and faces."""
        if self.vertices is None or self.faces is None:
            return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
        tri = self.vertices[self.faces]
        near = np.all((tri.min(axis=1) <= hi) & (tri.max(axis=1) >= lo), axis=1)
        picked = tri[near].reshape(-1, 3)
        return picked, np.arange(len(picked), dtype=np.int64).reshape(-1, 3)


def area_rooms(areas: list[AreaSpec]) -> tuple[dict[str, Room], dict[str, Segment]]:
    """Each area as a room whose door is the middle of its entry side, grouped in segments
    by the first three parts of its id."""
    rooms: dict[str, Room] = {}
    segments: dict[str, list[str]] = {}
    for area in areas:
        group, level, _, _ = area.id.split(".")
        segment = area.id.rsplit(".", 1)[0]
        lo, hi = area.box
        box = Box(lo, hi)
        rooms[area.id] = Room(area.id, group, int(level), segment, box, _door(box, area.entry),
                              "outdoor")
        segments.setdefault(segment, []).append(area.id)
    return rooms, {s: Segment(s, ids[0].split(".")[0], int(ids[0].split(".")[1]), tuple(ids))
                   for s, ids in segments.items()}


def _door(box: Box, side: str) -> Door:
    (x0, y0, z), (x1, y1, z1) = box.lo, box.hi
    xc, yc = (x0 + x1) / 2, (y0 + y1) / 2
    center, axis, span = {"south": ((xc, y0, z), 1, x1 - x0), "north": ((xc, y1, z), 1, x1 - x0),
                          "west": ((x0, yc, z), 0, y1 - y0), "east": ((x1, yc, z), 0, y1 - y0),
                          }[side]
    return Door(center, axis, min(DOOR_WIDTH, span / 2), z1 - z)


def ground_slab(site: tuple[float, float]) -> Solid:
    """The ground under an imported site, as a slab whose top is ``z = 0``: the floor that
    furniture is placed on and robots stand on (physics has its plane there already)."""
    return Solid("slab", Box((0.0, 0.0, -GROUND_DEPTH), (site[0], site[1], 0.0)), "ground")


def load_geometry(spec: GeometrySpec, source: SourceSpec | None,
                  doc: LocatedYaml) -> tuple[list[Solid], Imported]:
    """Read the files beside the world file; a missing or broken one is an InputError that
    names it and the key that refers to it."""
    blocks: list[Solid] = []
    if spec.blocks is not None:
        arrays = _npz(doc.file_at(("geometry", "blocks"), spec.blocks), doc, "blocks",
                      ("boxes", "voxel"))
        voxel = float(arrays["voxel"])
        if abs(voxel - spec.voxel) > 1e-9:
            raise doc.error(("geometry", "voxel"), f"{spec.voxel:g} m, but {spec.blocks} holds "
                            f"boxes of {voxel:g} m voxels")
        corners = np.asarray(arrays["boxes"], dtype=float).reshape(-1, 6) * voxel
        blocks = [Solid(BLOCK, Box(tuple(c[:3]), tuple(c[3:])), BLOCK) for c in corners.tolist()]
    vertices = faces = None
    mesh_file = doc.file_at(("geometry", "mesh"), spec.mesh) if spec.mesh is not None else None
    if mesh_file is not None:
        vertices, faces = _mesh(mesh_file, doc)
    cloud = colors = None
    if spec.cloud is not None:
        arrays = _npz(doc.file_at(("geometry", "cloud"), spec.cloud), doc, "cloud",
                      ("points", "colors"))
        cloud = np.asarray(arrays["points"], dtype=float).reshape(-1, 3)
        colors = np.asarray(arrays["colors"], dtype=np.uint8).reshape(-1, 3)
    parts = doc.file_at(("geometry", "parts"), spec.parts) if spec.parts is not None else None
    info = source.model_dump() if source is not None else {}
    return blocks, Imported(spec.voxel, spec.collision, info, tuple(spec.floors), mesh_file,
                            parts, vertices, faces, cloud, colors)


def _npz(path: Path, doc: LocatedYaml, key: str, names: tuple[str, ...]) -> dict[str, Any]:
    try:
        with np.load(path, allow_pickle=False) as data:
            missing = [n for n in names if n not in data.files]
            if missing:
                raise doc.error(("geometry", key), f"{path.name} holds no "
                                f"{', '.join(missing)}")
            return {n: data[n] for n in names}
    except InputError:
        raise
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise doc.error(("geometry", key), f"{path.name} is not a readable .npz file "
                        f"({' '.join(str(exc).split())})") from None


def _mesh(path: Path, doc: LocatedYaml) -> tuple[FloatArray, NDArray[np.int64]]:
    import trimesh

    try:
        mesh: Any = trimesh.load(path, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many kinds for a bad file
        raise doc.error(("geometry", "mesh"), f"{path.name} is not a readable mesh "
                        f"({' '.join(str(exc).split())})") from None
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        raise doc.error(("geometry", "mesh"), f"{path.name} has no faces")
    return np.asarray(mesh.vertices, dtype=np.float64), faces
