"""LAS and LAZ (laspy, with its lazrs backend for LAZ): every version and point format, units
from the header's coordinate system."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from astralis_des.errors import InputError
from astralis_des.importers.pointcloud import library_error
from astralis_des.importers.source import (
    FOOT,
    US_SURVEY_FOOT,
    Cloud,
    ReadRequest,
    check_memory,
    reader,
)

LAS_BYTES_PER_POINT = 150  # memory while importing: the record, float copies, indices
# EPSG codes of linear units in a GeoTIFF key directory (ProjLinearUnitsGeoKey, 3076).
LINEAR_UNITS = {9001: ("m", 1.0), 9002: ("ft", FOOT), 9003: ("US survey ft", US_SURVEY_FOOT)}
PROJ_LINEAR_UNITS, VERTICAL_UNITS = 3076, 4099
_WKT_UNIT = re.compile(r'(?:LENGTH)?UNIT\[\s*"([^"]+)"\s*,\s*([0-9.eE+-]+)')
_ANGULAR = ("degree", "radian", "grad", "arc")


@reader("las", "laz", memory_per_byte=0.0)
def read_las(path: Path, request: ReadRequest) -> Cloud:
    """LAS 1.0 to 1.4, compressed (LAZ) or not; units from the header's CRS when present."""
    import laspy

    what = path.suffix.lstrip(".").upper()
    try:
        with laspy.open(path) as opened:
            count = int(opened.header.point_count)
        check_memory(path, count * LAS_BYTES_PER_POINT, f"a cloud of {count:,} points")
        las = laspy.read(path)
    except InputError:
        raise
    except Exception as exc:  # laspy and lazrs raise many kinds for a bad file
        raise library_error(path, what, exc) from None
    if len(las.points) < count:
        raise InputError(f"truncated: the header announces {count:,} points, the file holds "
                         f"{len(las.points):,}", file=path)
    xyz = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    names = set(las.point_format.dimension_names)
    classification = np.asarray(las.classification, dtype=np.uint8) \
        if "classification" in names else None
    colors = None
    if {"red", "green", "blue"} <= names:
        rgb = np.column_stack([np.asarray(las.red), np.asarray(las.green), np.asarray(las.blue)])
        colors = (rgb >> 8 if rgb.max(initial=0) > 255 else rgb).astype(np.uint8)
    scale, vertical, note = _las_units(las.header)
    return Cloud(xyz, classification, colors, scale, vertical, note, _las_crs(las.header))


def _las_crs(header: Any) -> str | None:
    """The header's coordinate system as WKT (from its WKT or GeoTIFF keys, by laspy and
    pyproj), or None."""
    try:
        crs = header.parse_crs()
    except Exception:  # no pyproj, or keys pyproj cannot read: no georeference
        return None
    return None if crs is None else str(crs.to_wkt())


def _las_units(header: Any) -> tuple[float | None, float | None, str]:
    """Metres per horizontal and vertical unit from the GeoTIFF keys, else the WKT."""
    for vlr in header.vlrs:
        keys = {k.id: k.value_offset for k in getattr(vlr, "geo_keys", [])}
        if PROJ_LINEAR_UNITS in keys and keys[PROJ_LINEAR_UNITS] in LINEAR_UNITS:
            name, scale = LINEAR_UNITS[keys[PROJ_LINEAR_UNITS]]
            vertical = LINEAR_UNITS.get(keys.get(VERTICAL_UNITS, -1), (None, None))[1]
            return (scale, vertical, f"{name} (EPSG {keys[PROJ_LINEAR_UNITS]}, "
                    "from the header's GeoTIFF keys)")
    for vlr in header.vlrs:
        text = getattr(vlr, "string", None)
        if isinstance(text, bytes):
            text = text.decode("ascii", "replace")
        if not isinstance(text, str):
            continue
        linear = [(n, float(f)) for n, f in _WKT_UNIT.findall(text)
                  if not any(a in n.lower() for a in _ANGULAR)]
        if linear:
            name, scale = linear[0]
            vertical = linear[1][1] if len(linear) > 1 else None
            return scale, vertical, f"{name} ({scale:g} m, from the header's WKT)"
    return None, None, ""
