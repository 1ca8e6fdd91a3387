"""Writing an imported world: the world file and the files beside it, all or nothing.

Everything is written into a staging folder next to the target
(:class:`~astralis_des.outdir.Staging`: locked against a second writer), the world file is
loaded back from there as a mission would load it, and only then are the files renamed into
place, the world file last. An error or an interruption leaves nothing half-written.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numpy as np
import yaml

from astralis_des.importers.mesh import decimals_for
from astralis_des.importers.options import Built
from astralis_des.outdir import Staging

MAX_INDEX = np.iinfo(np.uint16).max


def write_world(built: Built, source: Path, out: Path, name: str, command: str) -> list[Path]:
    """Write ``out`` (a ``.yaml`` world) and its sidecars; return the paths written."""
    stem = out.name.rsplit(".", 1)[0]
    with Staging(out, file=True) as folder:
        geometry = _sidecars(built, folder, stem)
        doc = _document(built, source, out, name, geometry)
        text = _header(built, source, command) + _dump(doc) + areas_text(built) + \
            interior_text(built)
        (folder / out.name).write_text(text, encoding="utf-8")
        _check(folder / out.name)
    return [out.parent / str(file) for file in [
        *(geometry[k] for k in ("blocks", "mesh", "parts", "cloud") if k in geometry),
        out.name]]


def _check(path: Path) -> None:
    """Load the new world as a mission would; a failure is a bug of the importer."""
    from astralis_des.world.build import read_world

    read_world(path.resolve())  # not cached: the path is a temporary one


def _sidecars(built: Built, folder: Path, stem: str) -> dict[str, object]:
    geometry: dict[str, object] = {"voxel": built.voxel}
    if len(built.boxes) and int(built.boxes.max()) > MAX_INDEX:
        raise ValueError("voxel indices beyond uint16: grid_shape should have refused")
    geometry["blocks"] = f"{stem}.blocks.npz"
    np.savez_compressed(folder / f"{stem}.blocks.npz", boxes=built.boxes.astype(np.uint16),
                        voxel=np.float64(built.voxel))
    digits = decimals_for(built.voxel)
    if built.vertices is not None and built.faces is not None:
        geometry["mesh"] = f"{stem}.mesh.obj"
        _write_obj(folder / f"{stem}.mesh.obj", [(built.vertices, built.faces)], digits)
    geometry["collision"] = built.collision
    if built.parts is not None:
        geometry["parts"] = f"{stem}.parts.obj"
        _write_obj(folder / f"{stem}.parts.obj", built.parts, digits)
    if built.cloud is not None and len(built.cloud):
        geometry["cloud"] = f"{stem}.cloud.npz"
        colors = built.cloud_colors if built.cloud_colors is not None else _by_height(
            built.cloud)
        np.savez_compressed(folder / f"{stem}.cloud.npz", points=built.cloud.astype(np.float32),
                            colors=colors.astype(np.uint8))
    geometry["floors"] = [round(float(z), 3) for z in built.floors]
    return geometry


def _write_obj(path: Path, parts: list[tuple[np.ndarray, np.ndarray]], digits: int) -> None:
    """One OBJ object per part (PyBullet makes a compound of them, trimesh a scene)."""
    import trimesh

    meshes = [trimesh.Trimesh(v, f, process=False) for v, f in parts]
    target = meshes[0] if len(meshes) == 1 else trimesh.Scene(meshes)
    text = trimesh.exchange.obj.export_obj(target, include_normals=False, include_texture=False,
                                           include_color=False, digits=digits)
    path.write_text(text, encoding="utf-8")


def _by_height(points: np.ndarray) -> np.ndarray:
    """Blue low to yellow high, when the file has no colours."""
    z = points[:, 2]
    t = np.clip((z - z.min()) / max(float(np.ptp(z)), 1e-6), 0.0, 1.0)
    return np.column_stack([40 + 215 * t, 80 + 150 * t, 200 - 160 * t]).astype(np.uint8)


def _document(built: Built, source: Path, out: Path, name: str,
              geometry: dict[str, object]) -> dict[str, object]:
    info = {"file": Path(os.path.relpath(source.resolve(), out.parent.resolve())).as_posix(),
            "format": source.suffix.lower().lstrip("."), "kind": built.kind,
            "bytes": source.stat().st_size, "sha256": _sha256(source)}
    info.update({k: v for k, v in built.source.items()
                 if k not in ("kind", "origin") and v is not None})
    info["offset"] = [round(float(v), 4) for v in info["offset"]]  # type: ignore[attr-defined]
    site: dict[str, object] = {"size": [round(v, 3) for v in built.site]}
    if built.source.get("origin") is not None:  # georeferenced: where (0, 0, 0) lies
        site["origin"] = built.source["origin"]
    return {"name": name, "site": site, "source": info, "geometry": geometry}


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as data:
        for block in iter(lambda: data.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _dump(doc: dict[str, object]) -> str:
    return yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=100)


def _header(built: Built, source: Path, command: str) -> str:
    found = ("# The interior (storeys, rooms, doors, stairs) was found in it: correct it here,\n"
             "# and check it with astralis validate." if built.interior is not None else
             "# Search areas are boxes: edit, add or remove them.")
    lines = [f"# A digital twin imported from {source.name} ({built.kind}) by:",
             f"#   {command}",
             "# Geometry lives beside this file (blocks, mesh, cloud); re-running the command",
             "# rewrites them and this file.", *found.split("\n"), ""]
    return "\n".join(lines)


def areas_text(built: Built) -> str:
    """The ``areas:`` section, one flow mapping a line (easy to edit by hand)."""
    if not built.areas:
        return ""
    lines = ["areas:  # GROUP.LEVEL.SEGMENT.AREA; a mission searches a group segment by segment"]
    for a in built.areas:
        lo = ", ".join(f"{v:g}" for v in a.lo)
        hi = ", ".join(f"{v:g}" for v in a.hi)
        lines.append(f"  - {{id: {a.id}, box: [[{lo}], [{hi}]], entry: {a.entry}}}")
    return "\n".join(lines) + "\n"


def interior_text(built: Built) -> str:
    """The ``interior:`` section, a place, door or stairs a line (easy to correct by hand)."""
    if built.interior is None:
        return ""
    section = built.interior
    head = {k: v for k, v in section.items() if k not in ("storeys", "places", "doors",
                                                          "stairs")}
    lines = ["interior:  # places GROUP.STOREY.SEGMENT.ROOM (corridors, stairwells: segment 0)"]
    lines += [f"  {k}: {v}" for k, v in head.items()]
    for key in ("storeys", "places", "doors", "stairs"):
        items = section.get(key) or []
        lines.append(f"  {key}:" + ("" if items else " []"))
        lines += ["    - " + yaml.safe_dump(item, default_flow_style=True, width=10**6,
                                           sort_keys=False).strip() for item in items]
    return "\n".join(lines) + "\n"
