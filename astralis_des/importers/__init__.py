"""Real-world import: point clouds and meshes become worlds (digital twins) missions run in.

``import_world("scan.laz", "worlds/site.yaml")`` reads the file with the reader registered
for its extension (:data:`READERS`), builds the world's geometry (:mod:`.cloudworld` or
:mod:`.meshworld`) and writes the world file and the files beside it (:mod:`.writer`).
Readers import their libraries (laspy, trimesh) when called, so importing this package is
cheap.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from pathlib import Path

from astralis_des.errors import InputError
from astralis_des.importers import las, mesh, pcd, ply, pointcloud  # noqa: F401  (readers)
from astralis_des.importers.options import Built, ImportOptions, ImportReport
from astralis_des.importers.source import (
    READERS,
    Cloud,
    Mesh,
    ReadRequest,
    check_file,
    extension,
    lookup,
)

__all__ = ["READERS", "ImportOptions", "ImportReport", "formats", "import_world"]

log = logging.getLogger(__name__)
WORLD_SUFFIXES = (".yaml", ".yml")


def formats() -> list[str]:
    """The extensions a file may have to be imported."""
    return list(READERS)


def import_world(source: str | Path, out: str | Path, options: ImportOptions | None = None,
                 *, command: str | None = None,
                 progress: Callable[[int, int], None] | None = None) -> ImportReport:
    """Import ``source`` (a cloud or a mesh) as the world file ``out``; any problem with the
    input is an :class:`InputError`, and then nothing is written. ``progress`` hears of the
    points read, as (read, in all)."""
    from astralis_des.importers.cloudworld import cloud_world
    from astralis_des.importers.meshworld import mesh_world
    from astralis_des.importers.writer import write_world

    t0 = time.perf_counter()
    opts = options or ImportOptions()
    opts.check()
    path, target = Path(source), Path(out)
    if target.suffix.lower() not in WORLD_SUFFIXES:
        raise InputError(f"a world file ends in .yaml, not '{target.suffix}'", file=target,
                         key="-o")
    fmt = opts.format or extension(path)
    read = lookup(path, fmt)
    check_file(path, fmt)
    data = read(path, ReadRequest(opts.partial, opts.max_points, progress))
    if isinstance(data, Cloud):
        if len(data.xyz) == 0:
            raise InputError("the cloud has no points", file=path)
        built = cloud_world(data, path, opts, fmt)
    else:
        if not isinstance(data, Mesh) or len(data.faces) == 0:
            raise InputError("the mesh has no faces", file=path)
        built = mesh_world(data, path, opts)
    for note in built.notes:
        log.info("%s: %s", path, note)
    if not built.areas and opts.areas and not opts.indoor:  # a cloud's importer says why
        span = " x ".join(f"{v:,.1f}" for v in built.stats.get("extent", ()))
        raise InputError(f"no free floor of at least 4 m x 4 m for a search area: the mesh "
                         f"spans {span} m, the site {built.site[0]:g} x {built.site[1]:g} m "
                         f"with --margin {opts.margin:g}; a wider --margin gives areas on the "
                         "ground around it", file=path)
    name = opts.name or target.name.rsplit(".", 1)[0]
    written = write_world(built, path, target, name, command or _command(path, target, opts))
    report = ImportReport(
        world=target, files=tuple(written), kind=built.kind,
        points=int(built.source.get("points") or built.source.get("faces") or 0),
        dropped=int(built.source.get("dropped", 0)), units=str(built.source["units"]),
        scale=float(built.source["scale"]), site=built.site, blocks=len(built.boxes),
        areas=tuple(a.id for a in built.areas), floors=tuple(built.floors),
        ground=built.source.get("ground"), ground_share=built.stats.get("ground_share"),
        classified_share=built.stats.get("classified_share"),
        seconds=time.perf_counter() - t0, extra=dict(built.stats), notes=tuple(built.notes),
        voxel=built.voxel, **_found_inside(built))
    log.info("imported %s as %s in %.2f s", path, target, report.seconds)
    return report


def _found_inside(built: Built) -> dict[str, int]:
    """How many rooms (searched) and doors an indoor import found."""
    section = built.interior or {}
    rooms = [p for p in section.get("places", []) if p["kind"] in ("room", "hall")]
    return {"rooms": len(rooms), "doors": len(section.get("doors", []))}


def _command(path: Path, target: Path, opts: ImportOptions) -> str:
    """The CLI command that makes the same world, for the world file's header."""
    defaults = ImportOptions()
    flags = []
    for key, value in vars(opts).items():
        if value != getattr(defaults, key) and key != "name":
            flag = f"--{key.replace('_', '-')}"
            flags.append(flag if value is True else f"{flag} {value}")
    return " ".join(["astralis world import", path.as_posix(), "-o", target.as_posix(), *flags])
