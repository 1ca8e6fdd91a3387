"""How a cloud's coordinates become the world's metres (:class:`Frame`), and where the world
lies on the Earth.

The units come from the file's coordinate system: metres, feet or US survey feet, from the
LAS header's GeoTIFF keys or its WKT (pyproj reads both), or from ``--crs``. Longitude and
latitude (a geographic system such as EPSG 4326) are never taken as lengths: they are projected
with pyproj onto a transverse Mercator plane touching the Earth at the cloud's middle, where a
metre on the plane is a metre on the ground to within a few millimetres over a few kilometres.
A file with no coordinate system has its units guessed, and the guess is said with the way to
override it.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from astralis_des.errors import InputError
from astralis_des.importers.source import UNITS, Cloud
from astralis_des.world.geometry import FloatArray

log = logging.getLogger(__name__)

DEGREE_RESOLUTION = 1e-5  # a LAS scale this fine (about a metre in degrees) suggests degrees
DEGREE_EXTENT = 5.0  # degrees: a cloud this small in longitude and latitude may be in degrees
OVERRIDE = "--units m, ft or us-ft, or --crs (e.g. EPSG:32617)"


@dataclass(frozen=True)
class Frame:
    """File coordinates to metres: scaled per axis, or projected from longitude and latitude."""

    horizontal: float  # m per file unit across (1 when projected: the plane is in metres)
    vertical: float  # m per file unit up
    note: str  # the units and where they came from
    wkt: str | None  # the coordinate system of the file's coordinates (georeferences the world)
    guessed: bool = False
    projection: Any = None  # pyproj Transformer, (lon, lat) -> plane (x, y), or None

    def metres(self, xyz: FloatArray) -> FloatArray:
        """``(N, 3)`` file coordinates in metres: scaled, or projected onto the plane."""
        if self.projection is None:
            return np.asarray(xyz * np.array([self.horizontal, self.horizontal,
                                              self.vertical]))
        x, y = self.projection.transform(xyz[:, 0], xyz[:, 1])
        return np.column_stack([x, y, xyz[:, 2] * self.vertical])

    def file_xy(self, xy: FloatArray) -> tuple[float, float]:
        """Where ``xy`` (metres, in this frame) lies in the file's coordinates."""
        if self.projection is None:
            return (float(xy[0] / self.horizontal), float(xy[1] / self.horizontal))
        from pyproj.enums import TransformDirection

        lon, lat = self.projection.transform(float(xy[0]), float(xy[1]),
                                             direction=TransformDirection.INVERSE)
        return (float(lon), float(lat))


def frame_for(cloud: Cloud, units: str, crs_text: str | None, lo: FloatArray,
              hi: FloatArray) -> Frame:
    """The frame of ``cloud``: ``units`` and ``crs_text`` (the options) over the file's own
    coordinate system, over a guess; ``lo`` and ``hi`` bound its points in file units."""
    middle = (np.asarray(lo, dtype=float) + np.asarray(hi, dtype=float)) / 2
    crs = _given_crs(crs_text) if crs_text else _file_crs(cloud.crs_wkt)
    given = f"{units} (given)" if units != "auto" else None
    if units != "auto":
        scale = UNITS[units]
        return Frame(scale, scale, str(given), _wkt(crs))
    if crs_text:
        return _from_crs(crs, middle, "given by --crs")
    if cloud.crs_scale is not None:  # GeoTIFF linear-unit keys or the WKT's unit, as read
        return Frame(cloud.crs_scale, cloud.crs_vertical or cloud.crs_scale, cloud.crs_note,
                     cloud.crs_wkt)
    if crs is not None:
        return _from_crs(crs, middle, "from the file's coordinate system")
    return _guess(cloud, middle, float(np.max(np.asarray(hi) - np.asarray(lo))))


def _given_crs(text: str) -> Any:
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    try:
        return CRS.from_user_input(text)
    except CRSError as exc:
        raise InputError(f"'{text}' is not a coordinate system pyproj knows ({exc})",
                         key="--crs") from None


def _file_crs(wkt: str | None) -> Any:
    if wkt is None:
        return None
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    try:
        return CRS.from_wkt(wkt)
    except CRSError:
        return None


def _wkt(crs: Any) -> str | None:
    return None if crs is None else str(crs.to_wkt())


def _from_crs(crs: Any, middle: FloatArray, where: str) -> Frame:
    """Units of a pyproj CRS: its first axis's unit (a projected system), or a projection of
    longitude and latitude (a geographic one); heights from its vertical part, else metres
    for a geographic system and the horizontal unit for a projected one."""
    horizontal = crs.sub_crs_list[0] if crs.is_compound else crs
    units = linear_units(crs)
    if units is None:
        projection = _plane(horizontal, float(middle[0]), float(middle[1]))
        return Frame(1.0, _vertical_scale(crs) or 1.0, f"degrees of {horizontal.name} "
                     f"({where}), projected onto a transverse Mercator plane at the cloud's "
                     "middle", crs.to_wkt(), projection=projection)
    scale, vertical, unit = units
    return Frame(scale, vertical or scale, f"{unit} ({scale:g} m, {horizontal.name}, {where})",
                 crs.to_wkt())


def linear_units(crs: Any) -> tuple[float, float | None, str] | None:
    """Metres per unit across and up (None: the system does not say) and the unit's name, of
    a pyproj system in lengths (or the horizontal part of a compound one); None for one in
    longitude and latitude."""
    horizontal = crs.sub_crs_list[0] if crs.is_compound else crs
    if horizontal.is_geographic:
        return None
    axis = horizontal.axis_info[0] if horizontal.axis_info else None
    scale = float(axis.unit_conversion_factor) if axis is not None else 1.0
    return scale, _vertical_scale(crs), axis.unit_name if axis is not None else "metre"


def _vertical_scale(crs: Any) -> float | None:
    parts = crs.sub_crs_list if crs.is_compound else []
    for part in parts[1:]:
        if part.axis_info:
            return float(part.axis_info[0].unit_conversion_factor)
    return None


def _plane(geographic: Any, lon: float, lat: float) -> Any:
    """(lon, lat) of ``geographic`` to metres on a transverse Mercator plane touching the
    Earth at ``(lon, lat)``, on the same datum."""
    from pyproj import CRS, Transformer
    from pyproj.crs import ProjectedCRS
    from pyproj.crs.coordinate_operation import TransverseMercatorConversion

    if not (math.isfinite(lon) and math.isfinite(lat) and -180 <= lon <= 180 and
            -90 <= lat <= 90):
        raise InputError(f"the cloud's middle ({lon:g}, {lat:g}) is not a longitude and "
                         f"latitude; its coordinate system says degrees: pass {OVERRIDE}",
                         key="--crs")
    plane = ProjectedCRS(TransverseMercatorConversion(latitude_natural_origin=lat,
                                                      longitude_natural_origin=lon),
                         geodetic_crs=CRS(geographic.geodetic_crs))
    return Transformer.from_crs(geographic, plane, always_xy=True)


def _guess(cloud: Cloud, middle: FloatArray, extent: float) -> Frame:
    """No coordinate system: longitude and latitude if the coordinates fit them and are
    stored finely enough to be degrees, else metres; either way the note says how to change
    the guess."""
    span = np.asarray(middle, dtype=float)
    fine = cloud.resolution is not None and cloud.resolution <= DEGREE_RESOLUTION
    if fine and abs(span[0]) <= 180 and abs(span[1]) <= 90 and extent <= DEGREE_EXTENT:
        from pyproj import CRS

        wgs84 = CRS.from_epsg(4326)
        frame = _from_crs(wgs84, middle, "guessed: no coordinate system in the file, and its "
                          f"coordinates look like longitude and latitude; pass {OVERRIDE} "
                          "if they are not")
        return Frame(frame.horizontal, frame.vertical, frame.note, frame.wkt, True,
                     frame.projection)
    return Frame(1.0, 1.0, f"m (guessed: no coordinate system in the file; pass {OVERRIDE} "
                 "if it is not in metres)", None, True)
