"""A LAS header's units and coordinate system: the GeoTIFF keys' linear unit, else the WKT's
(in a VLR or, in LAS 1.4, an EVLR) as pyproj reads it."""

from __future__ import annotations

import math
import re
from typing import Any

from astralis_des.importers.crs import linear_units
from astralis_des.importers.source import FOOT, US_SURVEY_FOOT

# EPSG codes of linear units in a GeoTIFF key directory (ProjLinearUnitsGeoKey, 3076).
LINEAR_UNITS = {9001: ("m", 1.0), 9002: ("ft", FOOT), 9003: ("US survey ft", US_SURVEY_FOOT)}
PROJ_LINEAR_UNITS, VERTICAL_UNITS = 3076, 4099
_WKT_UNIT = re.compile(r'(?:LENGTH)?UNIT\[\s*"([^"]+)"\s*,\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)')
_ANGULAR = ("degree", "radian", "grad", "arc")


def las_crs(header: Any) -> str | None:
    """The header's coordinate system as WKT (from its WKT or GeoTIFF keys, by laspy and
    pyproj), or None."""
    try:
        crs = header.parse_crs()
    except Exception:  # keys or WKT pyproj cannot read: no georeference
        return None
    return None if crs is None else str(crs.to_wkt())


def las_units(header: Any) -> tuple[float | None, float | None, str]:
    """Metres per horizontal and vertical unit from the GeoTIFF keys, else the WKT (in a VLR
    or, in LAS 1.4, an EVLR)."""
    records = [*header.vlrs, *(header.evlrs or ())]
    for vlr in records:
        keys = {k.id: k.value_offset for k in getattr(vlr, "geo_keys", [])}
        if PROJ_LINEAR_UNITS in keys and keys[PROJ_LINEAR_UNITS] in LINEAR_UNITS:
            name, scale = LINEAR_UNITS[keys[PROJ_LINEAR_UNITS]]
            vertical = LINEAR_UNITS.get(keys.get(VERTICAL_UNITS, -1), (None, None))[1]
            return (scale, vertical, f"{name} (EPSG {keys[PROJ_LINEAR_UNITS]}, "
                    "from the header's GeoTIFF keys)")
    for vlr in records:
        text = getattr(vlr, "string", None)
        if isinstance(text, bytes):
            text = text.decode("ascii", "replace")
        units = _wkt_units(text) if isinstance(text, str) else None
        if units is not None:
            return units
    return None, None, ""


def _wkt_units(text: str) -> tuple[float, float | None, str] | None:
    """Metres per unit of a WKT's projected system (and of its vertical one) as pyproj reads
    them; from its UNIT keywords when pyproj cannot read it (the first one not of angles)."""
    from pyproj import CRS

    try:
        crs = CRS.from_wkt(text)
    except Exception:  # pyproj's CRSError, or worse for a damaged WKT
        linear = [(n, float(f)) for n, f in _WKT_UNIT.findall(text)
                  if not any(a in n.lower() for a in _ANGULAR) and math.isfinite(float(f))]
        if not linear:
            return None
        (name, scale), vertical = linear[0], linear[1][1] if len(linear) > 1 else None
        return scale, vertical, f"{name} ({scale:g} m, from the header's WKT)"
    parts = crs.sub_crs_list if crs.is_compound else [crs]
    units = linear_units(crs) if parts and parts[0].is_projected else None
    if units is None:
        return None  # degrees: projected where the frame is made
    scale, vertical, unit = units
    return scale, vertical, f"{unit} ({scale:g} m, from the header's WKT)"

