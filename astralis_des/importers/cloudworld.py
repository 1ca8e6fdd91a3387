"""A point cloud becomes a world: units to metres, recentred, the ground found and flattened
to ``z = 0``, what stands on it voxelised into blocks, search areas on the open ground, and a
downsampled cloud for the replay.

Heights are heights above the ground (a normalised height model): the physics ground is a
plane, so the terrain's relief (reported) is flattened, and whatever stands on it keeps its
height. ``fill: columns`` (aerial scans) makes each occupied column solid down to the ground,
since an aerial scanner sees the roof and not what is under it; ``none`` keeps the voxels the
points fall in (terrestrial and indoor scans, which see walls). A classified cloud (ASPRS
classes) is used as classified: ground (2) is the ground, buildings (6) and unclassified points
stand as the fill says (an aerial scan's building: a solid from its roof down), vegetation
(3-5) is canopy kept where its points are (a UAV plans round a crown, a walker passes under
it), noise (7, 18) is left out.

Everything runs in passes over chunks of the points (:mod:`.survey`), into grids no larger
than ``MAX_RASTER`` cells and sets of the voxels that hold points: memory follows the points,
not the extent. The voxel, unless given, follows the points' spacing.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np

from astralis_des.errors import InputError
from astralis_des.importers.cloudareas import cloud_areas
from astralis_des.importers.cloudbuild import build
from astralis_des.importers.density import SPARSE, choose_voxel, nice_up, raster_cell
from astralis_des.importers.ground import (
    GROUND_CLASS,
    WINDOW,
    Ground,
    Minima,
    grid_size,
    ground_of,
)
from astralis_des.importers.indoor_world import (
    HEADING_SAMPLE,
    indoor_heading,
    indoor_section,
    outside_interior,
)
from astralis_des.importers.options import Built, ImportOptions
from astralis_des.importers.source import Cloud
from astralis_des.importers.survey import Survey, sample, survey, turn_about, turned_survey
from astralis_des.importers.voxels import MAX_INDEX, cells_across

log = logging.getLogger(__name__)

FINEST = 10  # a voxel finer than a tenth of the points' spacing makes specks, not walls


def cloud_world(cloud: Cloud, path: Path, opts: ImportOptions, fmt: str) -> Built:
    """The world of ``cloud`` (read from ``path``, a ``fmt`` file)."""
    try:
        found = survey(cloud, opts.units, opts.crs, opts.scale, opts.keep_strays)
    except InputError as exc:
        raise InputError(exc.message, file=path, key=exc.key) from None
    notes = [*cloud.notes, f"units: {found.metres.frame.note}", *found.notes]
    heading = indoor_heading(sample(found, HEADING_SAMPLE), path) if opts.indoor else 0.0
    if heading:  # an indoor scan is turned so that its walls run along x and y
        found = turned_survey(found, -heading)
    voxel = _voxel(found, opts, path, notes)
    rng = np.random.default_rng(opts.seed)
    ground = _ground(cloud, found, opts, path, rng)
    origin = found.lo[:2] - opts.margin
    extent = found.hi[:2] - origin + opts.margin
    shape = cells_across(extent, voxel)
    aerial = fmt in ("las", "laz") and not opts.indoor
    fill = opts.fill if opts.fill != "auto" else ("columns" if aerial else "none")
    built = build(cloud, found, ground, origin, shape, voxel, fill, opts, rng)
    interior = None
    if opts.indoor and built.points is not None:
        interior, _ = indoor_section(built.points, opts.group, path, notes,
                                     opts.door_max, heading)  # its floor: the ground
        built.points = None
        built.boxes = outside_interior(built.boxes, voxel, interior)
    areas = [] if opts.indoor else cloud_areas(built, shape, voxel, found, opts, path, notes)
    frame = found.metres.frame
    corner = origin
    if found.metres.turn is not None:  # the origin, back in the file's frame
        angle, pivot = found.metres.turn
        corner = turn_about(np.array([[*origin, 0.0]]), -angle, pivot)[0, :2]
        if frame.wkt is not None:
            notes.append("not georeferenced: the world's x axis runs along the walls, "
                         "not east")
    file_xy = frame.file_xy(corner if frame.projection is None else corner / opts.scale)
    offset = (file_xy[0], file_xy[1], float(np.median(ground.heights) / frame.vertical))
    classes = cloud.classification
    classified = found.ground_class / found.kept if classes is not None and classes.any() \
        else None  # class 0 throughout: never classified
    share = built.ground_points / found.kept
    held = len(cloud) if cloud.held is None else cloud.held
    source = {"kind": "cloud", "points": held, "dropped": found.dropped, "units": frame.note,
              "scale": round(frame.horizontal, 9), "up": "z", "offset": offset,
              "ground": ground.method, "ground_share": round(share, 4),
              "relief": round(ground.relief, 2),
              "origin": None if heading else _geodetic(frame.wkt, offset, frame.vertical)}
    if found.strays:
        source["strays"] = found.strays
    if cloud.held is not None and cloud.held != len(cloud):
        source["kept"] = len(cloud)
    stats = {"ground_share": share, "classified_share": classified, "fill": fill,
             "standing": built.standing, "canopy": built.canopy, "spacing": found.spacing,
             "kept": found.kept, "strays": found.strays}
    return Built("cloud", (shape[0] * voxel, shape[1] * voxel), voxel, built.boxes, areas,
                 source, "boxes", floors=[0.0], cloud=built.cloud, cloud_colors=built.colors,
                 stats=stats, notes=notes, interior=interior)


def _voxel(found: Survey, opts: ImportOptions, path: Path, notes: list[str]) -> float:
    """The voxel: as given (unless far finer than the points, or too fine for the site), else
    the finest nice size no finer than the points' spacing."""
    span = float(np.max(found.hi[:2] - found.lo[:2])) + 2 * opts.margin
    rise = float(found.hi[2] - found.lo[2])  # the most a point can stand above the ground
    coarsest = max(span, rise) / MAX_INDEX  # boxes are stored as uint16 voxel indices
    spaced = (f"one point per {found.spacing:.3g} m: {found.kept:,} points over the "
              f"{found.area:,.0f} m^2 they cover")
    if opts.voxel is not None:
        smallest = max(found.spacing / FINEST, coarsest)
        if opts.voxel < smallest:
            raise InputError(f"{opts.voxel:g} m is too fine for this cloud ({spaced}; the "
                             f"site spans {span:,.0f} m): pass --voxel "
                             f"{math.ceil(smallest * 1000) / 1000:g} or more", file=path,
                             key="--voxel")
        return float(opts.voxel)
    voxel = choose_voxel(max(found.spacing, coarsest))
    if coarsest > voxel:
        raise InputError(f"the cloud spans {max(span, rise) / 1000:,.0f} km ({found.kept:,} "
                         "points): "
                         f"more than a world holds at {voxel:g} m voxels (65,535 a side); "
                         "crop it first", file=path)
    how = "the finest no finer than the points" if voxel >= found.spacing else \
        "the coarsest, though the points lie further apart"
    notes.append(f"voxel {voxel:g} m, {how} ({spaced}); --voxel to choose")
    if found.spacing > SPARSE:
        notes.append(f"warning: a sparse cloud, so a coarse world: {spaced}; blocks stand "
                     "only where points are")
    return voxel


def _ground(cloud: Cloud, found: Survey, opts: ImportOptions, path: Path,
            rng: np.random.Generator) -> Ground:
    method = opts.ground
    if method == "auto":
        method = "classification" if found.ground_class else "grid"
    if method == "classification" and not found.ground_class:
        raise InputError("the cloud has no points classified as ground (class 2)", file=path,
                         key="--ground")
    # Cells about as wide as the points are apart, up to the filter's window: a sparse cloud's
    # empty cells take their nearest point's height (measured on the corpus's sparse tiles
    # against their classification: 84-92% agree on what stands, 49-53% with 200 m cells).
    cell = 1.0 if found.spacing <= 1.0 else min(nice_up(found.spacing), WINDOW)
    cell = raster_cell(cell, found.hi[:2] - found.lo[:2])
    minima = Minima(found.lo[:2], cell, grid_size(found.hi[:2], found.lo[:2], cell))
    classes = cloud.classification
    for lo, hi, m in found.metres.chunks():
        keep = found.keep[lo:hi]
        mask = classes[lo:hi][keep] == GROUND_CLASS if method == "classification" and \
            classes is not None else None
        minima.add(m[keep], mask)
    return ground_of(minima, method, rng)


def _geodetic(wkt: str | None, offset: tuple[float, float, float],
              vertical: float) -> dict[str, float] | None:
    """Where the world's (0, 0, 0) lies on the Earth (WGS 84), from the file's coordinate
    system (pyproj): its ``offset`` in the file's units, its height in metres."""
    if wkt is None:
        return None
    from pyproj import CRS, Transformer
    from pyproj.exceptions import CRSError, ProjError

    try:
        to_wgs84 = Transformer.from_crs(CRS.from_wkt(wkt), "EPSG:4326", always_xy=True)
        lon, lat = to_wgs84.transform(offset[0], offset[1])
    except (CRSError, ProjError) as exc:  # a system pyproj cannot take to WGS 84: no georeference
        log.warning("the file's coordinate system gives no WGS 84 position (%s): the world "
                    "is not georeferenced", exc)
        return None
    if not (math.isfinite(lat) and math.isfinite(lon)):
        return None
    return {"latitude": round(float(lat), 7), "longitude": round(float(lon), 7),
            "altitude": round(offset[2] * vertical, 3)}
